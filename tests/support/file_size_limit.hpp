// "Disk full" for this process in a test: files may not grow past `bytes` (writes fail with
// EFBIG, as they would with ENOSPC; SIGXFSZ ignored). Lifted by lift() or the destructor.
#pragma once

#include <sys/resource.h>

#include <csignal>

namespace eical::testing {

class FileSizeLimit {
 public:
  explicit FileSizeLimit(rlim_t bytes) {
    ::getrlimit(RLIMIT_FSIZE, &old_);
    handler_ = std::signal(SIGXFSZ, SIG_IGN);
    rlimit small = old_;
    small.rlim_cur = bytes;
    ::setrlimit(RLIMIT_FSIZE, &small);
  }
  ~FileSizeLimit() { lift(); }
  FileSizeLimit(const FileSizeLimit&) = delete;
  FileSizeLimit& operator=(const FileSizeLimit&) = delete;
  void lift() {
    if (lifted_) return;
    ::setrlimit(RLIMIT_FSIZE, &old_);
    std::signal(SIGXFSZ, handler_);
    lifted_ = true;
  }

 private:
  rlimit old_{};
  void (*handler_)(int) = SIG_DFL;
  bool lifted_ = false;
};

}  // namespace eical::testing
