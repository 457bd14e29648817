#pragma once
// What the G-code fuzz targets (one per dialect) check: the reader ends in a program the
// interpolator can rely on or an InputError naming the file; a program it read is kept as
// canonical text (what simulate stores) that eical reads back without an error.
#include "fuzz/fuzz_support.hpp"
#include "sim/gcode/canonical.hpp"
#include "sim/gcode/parser.hpp"

#include <cmath>
#include <numbers>

namespace eical::fuzz {

inline void check_program(const sim::gcode::Program& p) {
  if (p.blocks.size() != p.source.size()) finding("blocks and source lines differ in number");
  for (const auto& b : p.blocks) {
    if (const auto* l = std::get_if<sim::gcode::Linear>(&b)) {
      if (!l->from_mm.allFinite() || !l->to_mm.allFinite())
        finding("a linear move with a coordinate that is not finite");
      if (!l->rapid && !(l->feed_mm_min > 0.0 && std::isfinite(l->feed_mm_min)))
        finding("a feed move without a positive finite feed");
    } else if (const auto* a = std::get_if<sim::gcode::Arc>(&b)) {
      if (!a->from_mm.allFinite() || !a->to_mm.allFinite() || !a->center_mm.allFinite())
        finding("an arc with a coordinate that is not finite");
      const double s = std::abs(a->sweep_rad);
      if (!(s > 0.0 && s <= 2.0 * std::numbers::pi + 1e-9)) finding("an arc whose sweep is not in (0, 2 pi]");
      if (!(a->feed_mm_min > 0.0 && std::isfinite(a->feed_mm_min))) finding("an arc without a positive finite feed");
    } else if (const auto* d = std::get_if<sim::gcode::Dwell>(&b)) {
      if (!(d->duration_s >= 0.0 && std::isfinite(d->duration_s))) finding("a dwell that is negative or not finite");
    }
  }
}

// Coordinates where the canonical text's nanometre digits still carry the arc's radius
// check (doubles keep ~16 digits).
inline bool within_machine_range(const sim::gcode::Program& p) {
  auto ok = [](const Eigen::Vector3d& v) { return v.cwiseAbs().maxCoeff() < 1e5; };
  for (const auto& b : p.blocks) {
    if (const auto* l = std::get_if<sim::gcode::Linear>(&b); l && !(ok(l->from_mm) && ok(l->to_mm))) return false;
    if (const auto* a = std::get_if<sim::gcode::Arc>(&b); a && !(ok(a->to_mm) && ok(a->center_mm))) return false;
  }
  return true;
}

inline void read_dialect(std::string_view text, sim::gcode::Dialect d) {
  const std::string name = std::string("fuzz-") + sim::gcode::dialect_name(d) + ".nc";
  expect_clean(name, [&] {
    const sim::gcode::Program p = sim::gcode::parse(text, name, {.dialect = d});
    check_program(p);
    const std::string kept = sim::gcode::canonical_gcode(text, name, d);
    if (!within_machine_range(p)) return;
    try {
      check_program(sim::gcode::parse(kept, "canonical"));
    } catch (const dsp::InputError& e) {
      finding(std::string("the canonical text of a program read is not readable: ") + e.what());
    }
  });
}

}  // namespace eical::fuzz
