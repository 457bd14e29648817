#pragma once
// Whether a set-point stays within the machine's work envelope (dsp/core/work_envelope.hpp):
// the travel of each axis, the path speed and the path acceleration. Exact for eical's own
// interpolator (its path elements and feed profiles, whatever the program's length); other
// set-points (Klipper's sweep, another NC's servo positions) are sampled at 1 kHz, at most
// 10^7 points.
#include "dsp/core/work_envelope.hpp"
#include "sim/nc/set_point.hpp"

#include <optional>
#include <string>

namespace eical::sim::nc {

enum class EnvelopeLimit { travel, feed, accel };

// The first limit the set-point exceeds and by what: for travel, the axis and the position
// it reaches beyond it (mm); for feed the peak path speed (mm/min); for acceleration the
// peak path acceleration (mm/s²).
struct EnvelopeExcess {
  EnvelopeLimit limit = EnvelopeLimit::travel;
  int axis = 0;  // travel: 0, 1, 2 = x, y, z
  double value = 0.0;
};

std::optional<EnvelopeExcess> envelope_excess(const SetPoint& set_point, const dsp::WorkEnvelope& envelope);

// "the program reaches x = 100010 mm, beyond the x travel -500..500 mm (travel_x_mm)":
// the limit, the value and the [envelope] key that sets it.
std::string describe(const EnvelopeExcess& excess, const dsp::WorkEnvelope& envelope);

// The option or key that sets the limit: "travel_x_mm", "max_feed_mm_min", "max_accel_mm_s2".
const char* envelope_key(const EnvelopeExcess& excess);

}  // namespace eical::sim::nc
