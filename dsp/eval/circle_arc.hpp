#pragma once
// Partial-arc circular test (ISO 230-4 permits arcs below 360°, e.g. 220° in a vertical
// plane where a full circle would hit the table).
//
// Centre: the PROGRAMMED centre, not a fitted one. A least-squares centre over a partial
// arc is poorly determined (over 220° a centre offset and a radius change are nearly
// collinear in the radial deviation, so noise and form errors move the fitted centre and
// radius together); a ballbar on a partial arc likewise measures from its pivot at the
// programmed centre. eical's measured path is in the set-point frame (it starts at the
// set-point), so the programmed centre is the same point in both. The consequence, stated
// in the report: a true centre offset e (e.g. a fixture or integration offset) appears as
// e·cos(θ − φ) in the radius deviation and enters G and F — as it would on a ballbar.
//
// Over the arc: radius deviation = |p − c_prog| − R_nominal; mean radius deviation; F_max,
// F_min (ISO 230-4 radial deviation); G = F_max − F_min (the two concentric circles about
// the fixed centre). H needs both directions: combine() in circle.hpp.
#include "dsp/eval/circle.hpp"

namespace eical::dsp::eval {

// in.segments are the evaluated arcs ([begin, end) sample indices, one direction),
// in.center_mm the programmed centre, arc_deg the programmed arc. Throws InputError when
// there is no segment, a segment holds fewer than 20 samples or a position is not finite.
CircleResult evaluate_arc(const CircleInput& in, double arc_deg);

}  // namespace eical::dsp::eval
