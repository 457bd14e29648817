#include "tests/faults/harness/eicald_process.hpp"

#include "drivers/dds/domain_claim.hpp"
#include "tests/faults/harness/recording_dir.hpp"

#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <cstdlib>
#include <fstream>
#include <thread>

namespace eical::faults {

fs::path write_eicald_config(const fs::path& dir, const fs::path& recording_dir, const std::string& extra) {
  const fs::path file = dir / "eicald.toml";
  std::ofstream os(file);
  os << "[source]\nkind = \"sim\"\npacing = \"free_running\"\nretry_s = 0.2\n"
     << "[source.sim]\nrepeats = 2\nidle_s = 0.2\nrepeat_program = true\n"
     << extra << "\n"
     << "[triggers]\ninputs = [\"frame\"]\n"
     << "[dds]\ndomain_id = " << drivers::dds::claim_free_domain() << "\nstatus_rate_hz = 20.0\n"
     << "config_uri = \"file://" EICAL_SOURCE_DIR "/config/cyclonedds-loopback.xml\"\n"
     << "[recording]\ndir = \"" << recording_dir.string() << "\"\ngzip = true\n"
     << "[limits]\nmax_measurement_s = 30.0\n"
     << "[realtime]\nsched_fifo_priority = 0\nmlockall = false\n";
  return file;
}

EicaldProcess::EicaldProcess(const fs::path& config, const fs::path& log_file,
                             const std::vector<std::pair<std::string, std::string>>& env)
    : log_file_(log_file) {
  pid_ = ::fork();
  if (pid_ == 0) {
    const int fd = ::open(log_file.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
    if (fd >= 0) ::dup2(fd, 1), ::dup2(fd, 2);
    for (const auto& [k, v] : env) ::setenv(k.c_str(), v.c_str(), 1);
    const std::string bin = EICALD_BIN, cfg = config.string();
    ::execl(bin.c_str(), bin.c_str(), "--config", cfg.c_str(), static_cast<char*>(nullptr));
    ::_exit(127);
  }
}

EicaldProcess::~EicaldProcess() {
  if (running()) {
    ::kill(pid_, SIGKILL);
    (void)wait_exit(std::chrono::seconds(5));
  }
}

bool EicaldProcess::running() {
  if (pid_ <= 0 || status_) return false;
  int st = 0;
  if (::waitpid(pid_, &st, WNOHANG) == pid_) status_ = st;
  return !status_;
}

void EicaldProcess::signal(int sig) {
  if (running()) ::kill(pid_, sig);
}

std::optional<int> EicaldProcess::wait_exit(std::chrono::milliseconds timeout) {
  const auto end = std::chrono::steady_clock::now() + timeout;
  while (running() && std::chrono::steady_clock::now() < end) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  if (!status_) return std::nullopt;
  return WIFEXITED(*status_) ? WEXITSTATUS(*status_) : 128 + WTERMSIG(*status_);
}

std::string EicaldProcess::log() const { return slurp(log_file_); }

}  // namespace eical::faults
