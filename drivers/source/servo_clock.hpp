#pragma once
// Maps LinuxCNC servo cycle numbers onto CLOCK_MONOTONIC. The servo thread runs on a fixed
// period and a line can only arrive after its cycle (halsampler wakes about every 10 ms,
// then the pipe), so the smallest (arrival − number·period) seen bounds the clock offset
// from above and is reached by the freshest line of a burst (NTP's minimum filter). The
// minimum is taken over the current and the previous window of cycles, so it follows a
// slow rate difference between the servo clock and CLOCK_MONOTONIC.
// Written by one thread (observe), read by another (time_ns): the offset is an atomic.
#include <atomic>
#include <cstdint>
#include <limits>

namespace eical::drivers {

class ServoClock {
 public:
  explicit ServoClock(double period_s, std::int64_t window_cycles = 2000) noexcept
      : period_ns_(period_s * 1e9), window_(window_cycles) {}

  void observe(std::int64_t number, std::int64_t arrival_ns) noexcept {
    const auto off = arrival_ns - static_cast<std::int64_t>(static_cast<double>(number) * period_ns_);
    const std::int64_t w = number / window_;
    if (w != window_index_) prev_min_ = w == window_index_ + 1 ? cur_min_ : kNone, cur_min_ = kNone, window_index_ = w;
    if (off < cur_min_) cur_min_ = off;
    const std::int64_t best = prev_min_ < cur_min_ ? prev_min_ : cur_min_;
    offset_ns_.store(best, std::memory_order_release);
    // Delay of this line behind its cycle: the freshness of the stream.
    const std::int64_t delay = off - best;
    if (delay > max_delay_ns_) max_delay_ns_ = delay;
    delay_sum_ns_ += static_cast<double>(delay), ++observed_;
  }
  // CLOCK_MONOTONIC of servo cycle `number`; 0 before the first observation.
  [[nodiscard]] std::int64_t time_ns(std::int64_t number) const noexcept {
    const std::int64_t off = offset_ns_.load(std::memory_order_acquire);
    return off == kNone ? 0 : off + static_cast<std::int64_t>(static_cast<double>(number) * period_ns_);
  }
  [[nodiscard]] std::int64_t offset_ns() const noexcept { return offset_ns_.load(std::memory_order_acquire); }
  // Observer thread only: how late lines arrived behind their cycle.
  [[nodiscard]] double mean_delay_ms() const noexcept { return observed_ ? delay_sum_ns_ / static_cast<double>(observed_) * 1e-6 : 0.0; }
  [[nodiscard]] double max_delay_ms() const noexcept { return static_cast<double>(max_delay_ns_) * 1e-6; }

 private:
  static constexpr std::int64_t kNone = std::numeric_limits<std::int64_t>::max();
  double period_ns_;
  std::int64_t window_;
  std::int64_t window_index_ = -1, cur_min_ = kNone, prev_min_ = kNone;
  std::atomic<std::int64_t> offset_ns_{kNone};
  std::int64_t max_delay_ns_ = 0;
  double delay_sum_ns_ = 0.0;
  std::uint64_t observed_ = 0;
};

}  // namespace eical::drivers
