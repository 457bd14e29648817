#pragma once
// What an interrupted eicald (kill -9, power loss, the watchdog) can leave in its recording
// directory, put right at the next start: the run writer's temporaries (.<run>.tmp-N, a
// run being written; .<run>.old-N, a run moved aside for a replacement: restored when the
// replacement never arrived), result.json.tmp beside a run, the writability probe. Runs
// are renamed into place whole, so no run directory is ever half written; a run the
// service stopped before evaluating has no result.json and is listed for evaluation.
#include <cstddef>
#include <filesystem>
#include <vector>

namespace eical::daemon {

struct RecordingCleanup {
  std::size_t removed = 0;                         // temporaries removed
  std::size_t restored = 0;                        // runs moved back from .old-N
  std::vector<std::filesystem::path> unevaluated;  // run directories without result.json
};

// Never throws: what cannot be removed stays (and is counted as not removed).
RecordingCleanup clean_recording_dir(const std::filesystem::path& dir);

}  // namespace eical::daemon
