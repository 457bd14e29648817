#pragma once
// When did the acquisition thread have a sample? Wraps a Source and, after each block
// read, pushes (last sample index of the block, CLOCK_MONOTONIC now — or the source's own
// sample_time_ns when it knows better) into an SPSC ring of
// stamps. The stamp is pushed before the pump hands the block's frames to the frame ring,
// so the DSP thread always finds the stamp of a frame it holds. Allocation only in the
// constructor; push and lookup are lock-free and never block.
#include "drivers/ring/spsc_ring.hpp"
#include "drivers/source/source.hpp"

#include <ctime>
#include <memory>

namespace eical::drivers {

struct AcquisitionStamp {
  std::int64_t last_index;  // last sample index of the block
  std::int64_t t_ns;        // CLOCK_MONOTONIC when read() returned it
};

inline std::int64_t monotonic_ns() noexcept {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1000000000 + ts.tv_nsec;
}

class StampedSource final : public Source {
 public:
  explicit StampedSource(std::unique_ptr<Source> inner, std::size_t stamp_capacity = 4096)
      : inner_(std::move(inner)), stamps_(stamp_capacity) {}

  void open() override { inner_->open(); }
  [[nodiscard]] const dsp::RunMeta& meta() const override { return inner_->meta(); }
  std::size_t read(std::span<dsp::Frame> out) override {
    const std::size_t n = inner_->read(out);
    if (n > 0) {
      // A source that knows when its samples were taken says so; others: now.
      const std::int64_t taken_ns = inner_->sample_time_ns(out[n - 1].sample_index);
      (void)stamps_.push_or_drop({out[n - 1].sample_index, taken_ns != 0 ? taken_ns : monotonic_ns()});
    }
    return n;
  }
  [[nodiscard]] bool at_end() const override { return inner_->at_end(); }
  [[nodiscard]] std::string_view name() const override { return inner_->name(); }
  [[nodiscard]] Backpressure backpressure() const override { return inner_->backpressure(); }
  [[nodiscard]] std::int64_t sample_time_ns(std::int64_t sample_index) const override {
    return inner_->sample_time_ns(sample_index);
  }
  [[nodiscard]] SourceCounters counters() const override { return inner_->counters(); }
  void drain_diagnostics(const std::function<void(const std::string&)>& sink) override {
    inner_->drain_diagnostics(sink);
  }
  // Stamps dropped because the DSP thread fell far behind (their frames then map by the
  // last stamp seen).
  [[nodiscard]] std::uint64_t stamp_overruns() const noexcept { return stamps_.overruns(); }

  // DSP thread, frames in order: the acquisition time of `sample_index` (0 when unknown,
  // e.g. the stamp was dropped because the DSP thread fell far behind).
  std::int64_t acquired_ns(std::int64_t sample_index) noexcept {
    while (current_.last_index < sample_index) {
      AcquisitionStamp s{};
      if (!stamps_.try_pop(s)) return 0;
      current_ = s;
    }
    return current_.t_ns;
  }
  [[nodiscard]] const AcquisitionStamp& current_stamp() const noexcept { return current_; }
  // After the source was reopened its sample clock restarts.
  void reset_lookup() noexcept {
    AcquisitionStamp s{};
    while (stamps_.try_pop(s)) {
    }
    current_ = {-1, 0};
  }

 private:
  std::unique_ptr<Source> inner_;
  SpscRing<AcquisitionStamp> stamps_;
  AcquisitionStamp current_{-1, 0};
};

}  // namespace eical::drivers
