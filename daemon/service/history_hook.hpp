#pragma once
// eicald's side of the calibration history ([history] in eicald.toml): each evaluated
// result is handed to the history sink on the evaluation thread, after result.json is
// written. The hand-over only writes the spool file; the store (SQLite or PostgreSQL) is
// written by the sink's own thread, so a slow, locked or absent store never delays an
// evaluation, and what it cannot take waits in the spool (history/spool/sink.hpp).
#include "daemon/config/daemon_config.hpp"
#include "dsp/analysis/analyze_run.hpp"
#include "dsp/core/run.hpp"
#include "history/spool/sink.hpp"

#include <filesystem>
#include <string>

namespace eical::daemon {

class HistoryHook {
 public:
  // sensor_calibration: what the evaluation compensated with ("datasheet" or
  // "<method>: <file> (run <id>)").
  HistoryHook(const HistoryConfig& config, std::string sensor_calibration);

  // Evaluation thread. Never throws: a result that cannot become a record is logged.
  void append(const dsp::Run& run, const dsp::Analysis& analysis, const std::filesystem::path& run_dir);

  // Why results wait for the store (empty when it takes them), for Status.fault.
  [[nodiscard]] std::string problem() const { return sink_.problem(); }
  [[nodiscard]] const std::string& sensor_calibration() const { return sensor_calibration_; }

 private:
  std::string sensor_calibration_;
  history::Sink sink_;
};

}  // namespace eical::daemon
