#pragma once
// One trigger input's path to the DSP thread and back: requests in an SPSC ring (input
// thread → DSP thread), verdicts in another (DSP thread → input thread). The DSP thread
// only pops and pushes: no allocation, lock or wait on its side.
#include "daemon/triggers/trigger_request.hpp"
#include "drivers/ring/spsc_ring.hpp"

#include <poll.h>
#include <sys/eventfd.h>
#include <unistd.h>

#include <atomic>
#include <stdexcept>
#include <string>

namespace eical::daemon {

class TriggerChannel {
 public:
  explicit TriggerChannel(std::string name)
      : name_(std::move(name)), verdict_fd_(::eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC)) {
    if (verdict_fd_ < 0) throw std::runtime_error("trigger channel " + name_ + ": eventfd failed");
  }
  ~TriggerChannel() { ::close(verdict_fd_); }
  TriggerChannel(const TriggerChannel&) = delete;
  TriggerChannel& operator=(const TriggerChannel&) = delete;

  // Input thread.
  bool send(const TriggerRequest& r) noexcept { return requests_.push_or_drop(r); }
  bool take_verdict(TriggerVerdict& v) noexcept { return verdicts_.try_pop(v); }
  // Sleeps until a verdict is there (an eventfd the DSP thread signals), at most timeout_ms.
  void wait_verdict(int timeout_ms) noexcept {
    pollfd p{verdict_fd_, POLLIN, 0};
    if (::poll(&p, 1, timeout_ms) > 0) {
      std::uint64_t n = 0;
      (void)!::read(verdict_fd_, &n, sizeof n);
    }
  }
  // DSP thread.
  bool take_request(TriggerRequest& r) noexcept { return requests_.try_pop(r); }
  void answer(const TriggerVerdict& v) noexcept {
    (void)verdicts_.push_or_drop(v);
    (v.accepted ? accepted_ : refused_).fetch_add(1, std::memory_order_relaxed);
    const std::uint64_t one = 1;
    (void)!::write(verdict_fd_, &one, sizeof one);  // non-blocking; wakes a waiting commander
  }

  [[nodiscard]] const std::string& name() const noexcept { return name_; }
  [[nodiscard]] std::uint64_t accepted() const noexcept { return accepted_.load(std::memory_order_relaxed); }
  [[nodiscard]] std::uint64_t refused() const noexcept { return refused_.load(std::memory_order_relaxed); }
  [[nodiscard]] std::uint64_t dropped() const noexcept { return requests_.overruns() + verdicts_.overruns(); }

 private:
  std::string name_;
  drivers::SpscRing<TriggerRequest> requests_{64};
  drivers::SpscRing<TriggerVerdict> verdicts_{64};
  std::atomic<std::uint64_t> accepted_{0}, refused_{0};
  int verdict_fd_;
};

}  // namespace eical::daemon
