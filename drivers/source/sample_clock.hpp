#pragma once
// Maps the sample numbers of a stream on a fixed-rate clock (LinuxCNC servo cycles, DAQ
// samples) onto CLOCK_MONOTONIC. A sample can only arrive after it was taken (halsampler
// wakes about every 10 ms, a DAQ packet leaves after its last sample), so the smallest
// (arrival − number·period) seen bounds the clock offset from above and is reached by the
// freshest sample of a burst (NTP's minimum filter). The minimum is taken over the current
// and the previous window of samples, so it follows a slow rate difference between the
// stream's clock and CLOCK_MONOTONIC.
// Written by one thread (observe), read by others (time_ns, number_at): the offset is an
// atomic; the delay statistics belong to the observing thread.
#include <atomic>
#include <cmath>
#include <cstdint>
#include <limits>

namespace eical::drivers {

class SampleClock {
 public:
  explicit SampleClock(double period_s, std::int64_t window_samples = 2000) noexcept
      : period_ns_(period_s * 1e9), window_(window_samples) {}

  void observe(std::int64_t number, std::int64_t arrival_ns) noexcept {
    const auto off = arrival_ns - static_cast<std::int64_t>(static_cast<double>(number) * period_ns_);
    const std::int64_t w = number / window_;
    if (w != window_index_) prev_min_ = w == window_index_ + 1 ? cur_min_ : kNone, cur_min_ = kNone, window_index_ = w;
    if (off < cur_min_) cur_min_ = off;
    const std::int64_t best = prev_min_ < cur_min_ ? prev_min_ : cur_min_;
    offset_ns_.store(best, std::memory_order_release);
    // Delay of this sample behind its time: the freshness of the stream.
    const std::int64_t delay = off - best;
    if (delay > max_delay_ns_) max_delay_ns_ = delay;
    delay_sum_ns_ += static_cast<double>(delay), ++observed_;
  }
  // Forget everything (the stream restarted its numbering).
  void reset() noexcept {
    window_index_ = -1, cur_min_ = kNone, prev_min_ = kNone;
    offset_ns_.store(kNone, std::memory_order_release);
    max_delay_ns_ = 0, delay_sum_ns_ = 0.0, observed_ = 0;
  }
  [[nodiscard]] bool known() const noexcept { return offset_ns_.load(std::memory_order_acquire) != kNone; }
  // CLOCK_MONOTONIC of sample `number`; 0 before the first observation.
  [[nodiscard]] std::int64_t time_ns(std::int64_t number) const noexcept {
    const std::int64_t off = offset_ns_.load(std::memory_order_acquire);
    return off == kNone ? 0 : off + static_cast<std::int64_t>(static_cast<double>(number) * period_ns_);
  }
  // The (fractional) sample number taken at CLOCK_MONOTONIC `t_ns`; NaN before the first observation.
  [[nodiscard]] double number_at(std::int64_t t_ns) const noexcept {
    const std::int64_t off = offset_ns_.load(std::memory_order_acquire);
    return off == kNone ? std::nan("") : static_cast<double>(t_ns - off) / period_ns_;
  }
  // CLOCK_MONOTONIC of sample 0 (kNone before the first observation).
  [[nodiscard]] std::int64_t offset_ns() const noexcept { return offset_ns_.load(std::memory_order_acquire); }
  [[nodiscard]] double period_ns() const noexcept { return period_ns_; }
  // Observer thread only: how late samples arrived behind their time.
  [[nodiscard]] double mean_delay_ms() const noexcept {
    return observed_ ? delay_sum_ns_ / static_cast<double>(observed_) * 1e-6 : 0.0;
  }
  [[nodiscard]] double max_delay_ms() const noexcept { return static_cast<double>(max_delay_ns_) * 1e-6; }

  static constexpr std::int64_t kNone = std::numeric_limits<std::int64_t>::max();

 private:
  double period_ns_;
  std::int64_t window_;
  std::int64_t window_index_ = -1, cur_min_ = kNone, prev_min_ = kNone;
  std::atomic<std::int64_t> offset_ns_{kNone};
  std::int64_t max_delay_ns_ = 0;
  double delay_sum_ns_ = 0.0;
  std::uint64_t observed_ = 0;
};

}  // namespace eical::drivers
