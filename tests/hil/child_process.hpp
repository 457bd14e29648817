#pragma once
// A child process for hardware-in-the-loop tests: started with fork/exec, output to a log
// file, always reaped. Every wait has a timeout, and the destructor kills a child that is
// still running (SIGKILL), so a hanging eicald cannot hang the test.
#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

namespace eical::test {

class ChildProcess {
 public:
  ChildProcess(const std::vector<std::string>& argv, const std::string& log_file, bool stderr_too = true) {
    pid_ = ::fork();
    if (pid_ == 0) {
      const int fd = ::open(log_file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      if (fd >= 0) ::dup2(fd, 1);
      const int err = stderr_too ? fd : ::open("/dev/null", O_WRONLY);
      if (err >= 0) ::dup2(err, 2);
      std::vector<char*> args;
      for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
      args.push_back(nullptr);
      ::execv(args[0], args.data());
      ::_exit(127);
    }
  }
  ~ChildProcess() {
    if (running()) {
      ::kill(pid_, SIGKILL);
      (void)wait_exit(std::chrono::seconds(5));
    }
  }
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;

  [[nodiscard]] bool started() const { return pid_ > 0; }
  [[nodiscard]] pid_t pid() const { return pid_; }
  bool running() {
    if (pid_ <= 0 || status_) return false;
    int st = 0;
    if (::waitpid(pid_, &st, WNOHANG) == pid_) status_ = st;
    return !status_;
  }
  void signal(int sig) {
    if (running()) ::kill(pid_, sig);
  }
  // Exit status (WEXITSTATUS, or 128 + signal), nullopt when still running at the timeout.
  std::optional<int> wait_exit(std::chrono::milliseconds timeout) {
    const auto end = std::chrono::steady_clock::now() + timeout;
    while (running() && std::chrono::steady_clock::now() < end) ::usleep(20000);  // test side only
    if (!status_) return std::nullopt;
    return WIFEXITED(*status_) ? WEXITSTATUS(*status_) : 128 + WTERMSIG(*status_);
  }

 private:
  pid_t pid_ = -1;
  std::optional<int> status_;
};

// Runs a command to completion (timeout, then killed) and returns its standard output.
inline std::optional<std::string> run_capture(const std::vector<std::string>& argv, std::chrono::milliseconds timeout,
                                              int* exit_code = nullptr) {
  char tmpl[] = "/tmp/eical-hil-out-XXXXXX";
  const int fd = ::mkstemp(tmpl);
  if (fd < 0) return std::nullopt;
  ::close(fd);
  std::optional<int> rc;
  {
    ChildProcess p(argv, tmpl, /*stderr_too=*/false);
    rc = p.wait_exit(timeout);
  }
  std::string out;
  if (FILE* f = std::fopen(tmpl, "r")) {
    char buf[4096];
    std::size_t n;
    while ((n = std::fread(buf, 1, sizeof buf, f)) > 0) out.append(buf, n);
    std::fclose(f);
  }
  ::unlink(tmpl);
  if (exit_code) *exit_code = rc.value_or(-1);
  if (!rc) return std::nullopt;
  return out;
}

}  // namespace eical::test
