#include "drivers/source/fault_source.hpp"

#include <cmath>
#include <limits>

namespace eical::drivers {

FaultSource::FaultSource(std::unique_ptr<Source> inner, FaultPlan plan) : inner_(std::move(inner)), plan_(plan) {
  if (plan_.saturate_channel < 0 || plan_.saturate_channel >= dsp::kAccelChannels)
    throw SourceError("fault injection: saturate_channel must be 0..5, got " + std::to_string(plan_.saturate_channel));
}

void FaultSource::open() {
  inner_->open();
  fs_hz_ = inner_->meta().acquisition.fs_hz;
  ++opens_;
  dropped_ = 0;
  gap_pending_ = false;
}

bool FaultSource::within(std::int64_t index, double at_s, double for_s) const {
  if (at_s < 0) return false;
  const double t = static_cast<double>(index) / fs_hz_;
  return t >= at_s && t < at_s + for_s;
}

std::size_t FaultSource::read(std::span<dsp::Frame> out) {
  const std::size_t n = inner_->read(out);
  if (n > 0 && opens_ == 1 && plan_.fail_at_s >= 0 &&
      static_cast<double>(out[0].sample_index) / fs_hz_ >= plan_.fail_at_s)
    throw SourceError("injected fault: the DAQ stopped delivering at " + std::to_string(plan_.fail_at_s) + " s");
  const double full = std::ldexp(1.0, inner_->meta().acquisition.adc_bits - 1) - 1.0;
  std::size_t kept = 0;
  for (std::size_t i = 0; i < n; ++i) {
    dsp::Frame f = out[i];
    if (plan_.gap_at_s >= 0 && dropped_ < plan_.gap_frames &&
        static_cast<double>(f.sample_index) / fs_hz_ >= plan_.gap_at_s) {
      ++dropped_;  // lost in transit: the sample index jumps, as after a USB packet loss
      gap_pending_ = true;
      continue;
    }
    if (gap_pending_) f.flags |= dsp::frame_flag::gap_before, gap_pending_ = false;
    if (within(f.sample_index, plan_.saturate_at_s, plan_.saturate_s)) {
      f.accel_counts[plan_.saturate_channel] = static_cast<std::int32_t>(full);
      f.flags |= dsp::frame_flag::accel_saturated;  // the DAQ's overrange status bit
    }
    if (within(f.sample_index, plan_.nan_at_s, plan_.nan_s)) f.temp_c[1] = std::numeric_limits<float>::quiet_NaN();
    out[kept++] = f;
  }
  return kept;
}

}  // namespace eical::drivers
