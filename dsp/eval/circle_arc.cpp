#include "dsp/eval/circle_arc.hpp"

#include "dsp/core/error.hpp"
#include "dsp/core/index_span.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace eical::dsp::eval {

CircleResult evaluate_arc(const CircleInput& in, double arc_deg) {
  if (in.pos_mm.size() != in.sample_index.size())
    throw InputError("arc evaluation: positions and sample indices differ in length");
  if (!(in.radius_mm > 0.0)) throw InputError("arc evaluation: nominal radius must be positive");
  if (!(arc_deg > 0.0 && arc_deg <= 360.0)) throw InputError("arc evaluation: arc_deg must be in (0, 360]");
  if (in.segments.empty()) throw InputError("arc evaluation: no evaluated arc between two M102 marks");
  // 360 here would fit centres: an arc of the full circle is still about the programmed one.
  CircleAccumulator acc(
      {in.center_mm, in.radius_mm, in.direction, std::min(arc_deg, std::nextafter(360.0, 0.0)), 1, 0, in.keep_trace});
  require_ascending(in.sample_index, "arc evaluation");
  for (const auto& seg : in.segments) {
    const IndexSpan span = index_span(in.sample_index, seg.first, seg.second);
    acc.begin(span.size());
    for (std::size_t i = span.begin; i < span.end; ++i) acc.add(in.sample_index[i], in.pos_mm[i]);
    acc.end();
  }
  CircleResult r = acc.result();
  r.arc_deg = arc_deg;
  return r;
}

}  // namespace eical::dsp::eval
