// Fuzz target: G-code (RS-274 subset) through sim::gcode::parse, and what the interpolator
// relies on in the program it returns.
#include "fuzz/fuzz_support.hpp"
#include "sim/gcode/parser.hpp"

#include <cmath>
#include <numbers>

namespace {

using namespace eical;

void check(const sim::gcode::Program& p) {
  if (p.blocks.size() != p.source.size()) fuzz::finding("blocks and source lines differ in number");
  for (const auto& b : p.blocks) {
    if (const auto* l = std::get_if<sim::gcode::Linear>(&b)) {
      if (!l->from_mm.allFinite() || !l->to_mm.allFinite())
        fuzz::finding("a linear move with a coordinate that is not finite");
      if (!l->rapid && !(l->feed_mm_min > 0.0 && std::isfinite(l->feed_mm_min)))
        fuzz::finding("a feed move without a positive finite feed");
    } else if (const auto* a = std::get_if<sim::gcode::Arc>(&b)) {
      if (!a->from_mm.allFinite() || !a->to_mm.allFinite() || !a->center_mm.allFinite())
        fuzz::finding("an arc with a coordinate that is not finite");
      const double s = std::abs(a->sweep_rad);
      if (!(s > 0.0 && s <= 2.0 * std::numbers::pi + 1e-9)) fuzz::finding("an arc whose sweep is not in (0, 2 pi]");
      if (!(a->feed_mm_min > 0.0 && std::isfinite(a->feed_mm_min)))
        fuzz::finding("an arc without a positive finite feed");
    } else if (const auto* d = std::get_if<sim::gcode::Dwell>(&b)) {
      if (!(d->duration_s >= 0.0 && std::isfinite(d->duration_s)))
        fuzz::finding("a dwell that is negative or not finite");
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text = fuzz::as_text(data, size);
  fuzz::expect_clean("fuzz.ngc", [&] { check(sim::gcode::parse(text, "fuzz.ngc")); });
  return 0;
}
