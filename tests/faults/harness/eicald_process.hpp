#pragma once
// eicald as the machine runs it: the real binary as a child process with a configuration
// file of the case's own, output to a log file, extra environment (systemd's
// NOTIFY_SOCKET, WATCHDOG_USEC), every wait bounded and a child still running at the end
// killed, so a hung eicald cannot hang a case.
#include <sys/types.h>

#include <chrono>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace eical::faults {

namespace fs = std::filesystem;

// A configuration like base_config's (free-running simulator repeating its program,
// frame-channel triggers, loopback DDS on a domain of its own) plus `extra` TOML.
fs::path write_eicald_config(const fs::path& dir, const fs::path& recording_dir, const std::string& extra = {});

class EicaldProcess {
 public:
  EicaldProcess(const fs::path& config, const fs::path& log_file,
                const std::vector<std::pair<std::string, std::string>>& env = {});
  ~EicaldProcess();  // SIGKILL when still running
  EicaldProcess(const EicaldProcess&) = delete;
  EicaldProcess& operator=(const EicaldProcess&) = delete;

  [[nodiscard]] pid_t pid() const { return pid_; }
  bool running();
  void signal(int sig);
  // Exit code, or 128 + the signal; nullopt when still running at the timeout.
  std::optional<int> wait_exit(std::chrono::milliseconds timeout);
  [[nodiscard]] std::string log() const;

 private:
  pid_t pid_ = -1;
  fs::path log_file_;
  std::optional<int> status_;
};

}  // namespace eical::faults
