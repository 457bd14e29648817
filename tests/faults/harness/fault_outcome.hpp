#pragma once
// What one injected fault did to eicald: the row of the fault table (bench_faults) and
// what the fault tests (tests/faults) assert on. Every figure is measured by the case
// that fills it in, never assumed.
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

namespace eical::faults {

struct FaultOutcome {
  std::string fault;                    // what was injected
  std::string outcome;                  // what the service did (flag, Status.fault, log line)
  bool service_alive = false;           // measuring again after the fault (or restarted and measuring)
  bool flagged = false;                 // a result flagged degraded, or Status.fault naming the cause
  bool clean = false;                   // no temporary, torn or half-written run directory left
  std::size_t runs_before = 0;          // completed recordings before the fault ...
  std::size_t runs_intact = 0;          // ... still there afterwards, byte for byte, and readable
  std::size_t runs_after = 0;           // recordings written during and after the fault
  double recovery_s = std::nan("");     // the fault cleared (or injected) → measuring / writing again
  std::int64_t measurements_lost = -1;  // completed measurements the service did not record
  std::string data_lost;                // the same in words, with what the loss is when not 0
  std::vector<std::string> problems;    // what did not hold (empty: the case passed its checks)

  void problem(const std::string& p) { problems.push_back(p); }
};

}  // namespace eical::faults
