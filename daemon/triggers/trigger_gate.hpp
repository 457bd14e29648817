#pragma once
// The DSP thread's decision on an external trigger before it reaches the measurement
// session: an M101 while a measurement runs (or one is about to start from an M101 still
// waiting for its sample) is refused, so the running measurement continues untouched; an
// M102/M103 without a measurement is refused. The state is projected over the triggers
// already queued for later samples. Per frame: no allocation; pure logic, tested alone.
#include "daemon/triggers/trigger_request.hpp"

#include <array>
#include <cstddef>
#include <cstdint>

namespace eical::daemon {

class TriggerGate {
 public:
  // Per frame, before the session sees it: queued triggers whose sample has passed are
  // in the session's state now.
  void on_frame(std::int64_t sample_index) noexcept;
  // `state`: the session's state now; `sample_index`: where the trigger lands.
  TriggerVerdict decide(const TriggerRequest& r, std::int64_t sample_index, dsp::State state) noexcept;
  [[nodiscard]] std::size_t pending() const noexcept { return count_; }

 private:
  struct Queued {
    std::int64_t sample_index;
    int code;
  };
  std::array<Queued, 16> queued_{};
  std::size_t count_ = 0;
};

}  // namespace eical::daemon
