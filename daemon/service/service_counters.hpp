#pragma once
// What the DSP thread counts, published to the status thread without a lock: relaxed
// atomic stores per frame (plain moves on x86-64 and arm64), read about once a second.
#include "dsp/session/measurement_state.hpp"

#include <atomic>
#include <cstdint>

namespace eical::daemon {

struct ServiceCounters {
  std::atomic<std::uint64_t> frames{0};
  std::atomic<std::uint64_t> frames_lost{0};     // frames marked gap_before
  std::atomic<std::uint64_t> frames_flagged{0};  // frames with any quality flag
  std::atomic<std::uint64_t> bad_frames{0};      // non-finite channels the guard replaced
  std::atomic<std::uint64_t> measurements_started{0};
  std::atomic<std::uint64_t> measurements{0};      // completed (M103 or cut short)
  std::atomic<std::uint64_t> triggers_refused{0};  // by the measurement state machine
  std::atomic<std::uint64_t> triggers_late{0};     // external triggers applied after their sample
  std::atomic<std::uint64_t> trigger_queue_full{0};
  std::atomic<std::uint64_t> recorder_overflow{0};  // frames beyond the recorder's capacity
  std::atomic<std::uint64_t> handoffs_deferred{0};  // a finished measurement waited for the evaluator
  std::atomic<int> state{static_cast<int>(dsp::State::idle)};
  std::atomic<std::int64_t> sample_index{0};    // the last frame handled
  std::atomic<float> temp_c[2] = {0.0f, 0.0f};  // its case temperatures, table and head
  std::atomic<bool> faulted{false};             // the run loop is reopening a failed source
  // The last acquisition stamp the DSP thread saw (sample index on the DAQ clock,
  // CLOCK_MONOTONIC), and what the status thread makes of the rate (SourceRateWatch):
  // delivered / fs_hz when off, 0 when fine.
  std::atomic<std::int64_t> stamp_index{-1}, stamp_ns{0};
  std::atomic<double> source_rate_ratio{0.0};

  [[nodiscard]] dsp::State measurement_state() const noexcept {
    return static_cast<dsp::State>(state.load(std::memory_order_relaxed));
  }
};

}  // namespace eical::daemon
