#include "tests/faults/harness/fault_cases.hpp"

namespace eical::faults {

const std::vector<FaultCase>& all_cases() {
  static const std::vector<FaultCase> cases = {
      {"disk_full", disk_full_mid_recording},
      {"recording_dir_removed", recording_dir_removed},
      {"wall_clock_steps_back", wall_clock_steps_back},
      {"source_faster_than_real_time", source_faster_than_real_time},
      {"source_stalls", source_stalls},
      {"command_flood", command_flood},
      {"malformed_commands", malformed_commands},
      {"kill9_during_write", kill9_during_write},
      {"dsp_thread_hung", dsp_thread_hung},
  };
  return cases;
}

}  // namespace eical::faults
