#pragma once
// Fault injection for tests of the service (and for commissioning: "what does the HMI
// show when the DAQ saturates?"). Wraps a Source and, at given times on its sample clock,
// makes it fail, lose frames, saturate an accelerometer channel or deliver NaN in a float
// channel — each the way the real driver would present it (a SourceError, a sample-index
// jump flagged gap_before, full-scale counts flagged accel_saturated, a NaN temperature).
// A time < 0 disables that fault. The failure fires on the first open() only, so a
// service that reopens its source afterwards continues normally.
#include "drivers/source/source.hpp"

#include <cstdint>
#include <memory>

namespace eical::drivers {

struct FaultPlan {
  double fail_at_s = -1.0;      // read() throws SourceError from this time on (first open only)
  double gap_at_s = -1.0;       // frames from here are lost ...
  std::int64_t gap_frames = 0;  // ... this many
  double saturate_at_s = -1.0;  // accel channel at positive full scale from here ...
  double saturate_s = 0.0;      // ... for this long
  int saturate_channel = 3;     // 0..5: table x,y,z, head x,y,z
  double nan_at_s = -1.0;       // head temperature NaN from here ...
  double nan_s = 0.0;           // ... for this long
  // Not the source's: eicald's DSP thread stops handling frames from this time on (until
  // the service is stopped), as a hung computation would (the watchdog test). The source
  // wrapper ignores it; any() is about the source's faults.
  double hang_dsp_at_s = -1.0;

  [[nodiscard]] bool any() const { return fail_at_s >= 0 || gap_at_s >= 0 || saturate_at_s >= 0 || nan_at_s >= 0; }
};

class FaultSource final : public Source {
 public:
  FaultSource(std::unique_ptr<Source> inner, FaultPlan plan);

  void open() override;
  [[nodiscard]] const dsp::RunMeta& meta() const override { return inner_->meta(); }
  std::size_t read(std::span<dsp::Frame> out) override;
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

 private:
  [[nodiscard]] bool within(std::int64_t index, double at_s, double for_s) const;

  std::unique_ptr<Source> inner_;
  FaultPlan plan_;
  double fs_hz_ = 0.0;
  int opens_ = 0;
  std::int64_t dropped_ = 0;  // frames dropped so far by the gap
  bool gap_pending_ = false;  // the next delivered frame carries gap_before
};

}  // namespace eical::drivers
