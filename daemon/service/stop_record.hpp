#pragma once
// How the previous eicald ended, told by the next one. While it runs eicald keeps a state
// file in its recording directory (.eicald-state: pid and start time) and writes into it
// why it stopped feeding systemd's watchdog when it does; a clean stop removes it. A start
// that finds the file knows the previous eicald did not stop cleanly (the watchdog, a
// crash, kill -9, power lost) and, when it knew, why: the journal and Status.fault say so.
#include <filesystem>
#include <mutex>
#include <optional>
#include <string>

namespace eical::daemon {

class StopRecord {
 public:
  // Reads what the previous eicald left (previous()); nothing is written yet.
  explicit StopRecord(std::filesystem::path recording_dir);
  // How the previous eicald ended, when not cleanly: one line.
  [[nodiscard]] const std::optional<std::string>& previous() const { return previous_; }

  // This eicald runs (pid, start time); `why` non-empty: it is stalled, and why. Any
  // thread. Never throws: a state file that cannot be written is logged, not fatal.
  void running(const std::string& why = {});
  // A clean stop: the file goes.
  void stopped_cleanly();

  static constexpr const char* kFileName = ".eicald-state";

 private:
  std::filesystem::path file_;
  std::optional<std::string> previous_;
  std::string started_;
  std::mutex mu_;  // the DSP thread (start) and the status thread (stall) write it
};

}  // namespace eical::daemon
