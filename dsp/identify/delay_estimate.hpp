#pragma once
// The DAQ delay from the PSD strips: their lock-in outputs pass the same DAQ filter as the
// accelerometers, so a PSD reading at sample k is where the spot was at k − d. Against an
// undelayed position — the reference instrument's, or the set-point's — the readings lag by
//   y = x_psd(k) − c(k − d0) ≈ −((d − d0)/fs + τ_servo) · v   (+ offsets per strip and
// direction: mounting, backlash),
// so a least-squares line through y against the velocity v gives d (reference: τ_servo = 0)
// or d + τ_servo·fs (set-point). Three or more feeds separate the lag from backlash, which
// does not grow with the speed.
#include "dsp/core/run_meta.hpp"
#include "dsp/identify/sensor_identification.hpp"
#include "dsp/pipeline/pipeline.hpp"

namespace eical::dsp::identify {

enum class DelayReference { setpoint, reference };

// m must carry the raw trace (PipelineConfig::keep_raw). Invalid when there are fewer than
// two passes over a strip faster than 1 mm/s.
DelayEstimate estimate_delay(const Measurement& m, const RunMeta& meta, DelayReference against);

}  // namespace eical::dsp::identify
