#include "dsp/comp/axis_table.hpp"

#include "dsp/comp/lincomp.hpp"
#include "dsp/core/error.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace eical::dsp::comp {
namespace {

std::string mm(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%g", v);
  return b;
}

}  // namespace

char axis_letter(int axis) noexcept { return axis == 0 ? 'x' : axis == 1 ? 'y' : axis == 2 ? 'z' : '?'; }

double AxisTable::deviation_um(double at_mm, Approach a) const {
  return interpolate(pos_mm, a == Approach::forward ? forward_um : reverse_um, at_mm);
}

double AxisTable::mean_lost_motion_um() const {
  double s = 0.0;
  for (std::size_t i = 0; i < pos_mm.size(); ++i) s += reverse_um[i] - forward_um[i];
  return pos_mm.empty() ? 0.0 : s / static_cast<double>(pos_mm.size());
}

void validate(const AxisTable& t) {
  const std::string who = std::string("comp: ") + axis_letter(t.axis) + " table";
  if (t.pos_mm.size() < 2) throw InputError(who + " needs at least 2 points");
  if (t.forward_um.size() != t.pos_mm.size() || t.reverse_um.size() != t.pos_mm.size())
    throw InputError(who + ": positions and deviations differ in count");
  for (std::size_t i = 0; i < t.pos_mm.size(); ++i) {
    if (!std::isfinite(t.pos_mm[i]) || !std::isfinite(t.forward_um[i]) || !std::isfinite(t.reverse_um[i]))
      throw InputError(who + ": point " + std::to_string(i + 1) + " is not a finite number");
    if (i > 0 && !(t.pos_mm[i] > t.pos_mm[i - 1]))
      throw InputError(who + ": positions must increase; point " + std::to_string(i + 1) + " (" + mm(t.pos_mm[i]) +
                       " mm) follows " + mm(t.pos_mm[i - 1]) + " mm");
  }
}

AxisTable fold_lost_motion(int axis, const std::vector<double>& pos_mm, const std::vector<double>& mean_um,
                           double lost_motion_um) {
  AxisTable t;
  t.axis = axis;
  t.pos_mm = pos_mm;
  for (double m : mean_um) {
    t.forward_um.push_back(m - 0.5 * lost_motion_um);
    t.reverse_um.push_back(m + 0.5 * lost_motion_um);
  }
  return t;
}

AxisTable without_reversal(const AxisTable& t) {
  AxisTable m = t;
  for (std::size_t i = 0; i < t.pos_mm.size(); ++i) m.forward_um[i] = m.reverse_um[i] = t.mean_um(i);
  return m;
}

AxisTable resample(const AxisTable& t, double first_mm, double spacing_mm, int points) {
  validate(t);
  AxisTable r;
  r.axis = t.axis;
  for (int k = 0; k < points; ++k) {
    const double p = first_mm + k * spacing_mm;  // no accumulated rounding
    if (p < t.first_mm() - 1e-9 || p > t.last_mm() + 1e-9)
      throw InputError(std::string("comp: the ") + axis_letter(t.axis) + " grid point " + mm(p) +
                       " mm lies outside the measured " + mm(t.first_mm()) + " .. " + mm(t.last_mm()) +
                       " mm (eical does not extrapolate a measurement)");
    r.pos_mm.push_back(p);
    r.forward_um.push_back(t.deviation_um(p, Approach::forward));
    r.reverse_um.push_back(t.deviation_um(p, Approach::reverse));
  }
  return r;
}

void require_coverage(const AxisTable& t, double from_mm, double to_mm, const std::string& who) {
  // 1 µm: a circle's programmed extreme that equals the last target is covered.
  if (from_mm >= t.first_mm() - 1e-3 && to_mm <= t.last_mm() + 1e-3) return;
  const char a = axis_letter(t.axis);
  throw InputError(std::string("comp: the ") + a + " table covers " + mm(t.first_mm()) + " .. " + mm(t.last_mm()) +
                   " mm, but " + who + " " + a + " from " + mm(from_mm) + " to " + mm(to_mm) +
                   " mm: measure positioning over that range (beyond its ends a control holds the end value)");
}

double residual_after_um(const AxisTable& t, const AxisTable& applied) {
  double worst = 0.0;
  for (std::size_t i = 0; i < t.pos_mm.size(); ++i)
    for (Approach a : {Approach::forward, Approach::reverse}) {
      const double dev = a == Approach::forward ? t.forward_um[i] : t.reverse_um[i];
      worst = std::max(worst, std::abs(dev + applied.correction_um(t.pos_mm[i], a)));
    }
  return worst;
}

}  // namespace eical::dsp::comp
