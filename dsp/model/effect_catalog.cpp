#include "dsp/model/effect_catalog.hpp"

#include "dsp/core/float_limits.hpp"
#include "dsp/pipeline/coriolis.hpp"

#include <Eigen/QR>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

namespace eical::dsp::model {
namespace {

constexpr double kPi = std::numbers::pi;
const char* const kAxisName[3] = {"x", "y", "z"};

std::string ax(int a) { return kAxisName[a]; }

double max_abs(const Eigen::VectorXd& p) { return p.size() ? p.cwiseAbs().maxCoeff() : 0.0; }

EffectModel effect(const char* name) {
  EffectModel e;
  e.name = name;
  return e;
}

Eigen::MatrixXd on_axis(const Eigen::VectorXd& v, int a) {
  Eigen::MatrixXd c = Eigen::MatrixXd::Zero(v.size(), 3);
  c.col(a) = v;
  return c;
}

double hint_corr(const Eigen::MatrixXd& hint, const Eigen::VectorXd& col, int axis) {
  if (hint.rows() != col.size()) return 0.0;
  double sxy = 0.0, sxx = 0.0, syy = 0.0;
  for (Eigen::Index s = 0; s < col.size(); ++s) {
    const double y = hint(s, axis);
    if (!std::isfinite(y)) continue;
    sxy += col[s] * y, sxx += col[s] * col[s], syy += y * y;
  }
  return sxx > 0.0 && syy > 0.0 ? std::abs(sxy) / std::sqrt(sxx * syy) : 0.0;
}

// Slide minus command of a play operator of width `play_um` (starting centred), per µm of
// play: −½ against the direction of motion once the play is taken up.
Eigen::VectorXd play_operator_column(const Eigen::VectorXd& cmd_mm, double play_um) {
  const double half_mm = 0.5 * play_um * 1e-3;
  Eigen::VectorXd col(cmd_mm.size());
  double slide = cmd_mm.size() ? cmd_mm[0] : 0.0;
  for (Eigen::Index s = 0; s < cmd_mm.size(); ++s) {
    slide = std::clamp(slide, cmd_mm[s] - half_mm, cmd_mm[s] + half_mm);
    col[s] = (slide - cmd_mm[s]) * 1e3 / play_um;
  }
  return col;
}

double get(const std::map<std::string, double>& v, const std::string& k) {
  const auto it = v.find(k);
  return it == v.end() ? 0.0 : it->second;
}

// The acceleration the acceleration-level effects act on: the set-point's, mm/s². The
// measured acceleration holds the sensors' noise, whose double integral is the very
// residual being explained: as a regressor it fits that noise (a scale "found" in a slow
// move, a nonlinearity in the slips of a creeping slide). The slide follows its set-point
// within the servo's lag, a few milliseconds, far below the scale of these effects.
Eigen::MatrixXd driven_acceleration(const RunResiduals& r) { return r.a_cmd; }

}  // namespace

void axis_directions(const RunResiduals& run, int axis, Eigen::VectorXd& dir, std::vector<int>& reversals) {
  dir = Eigen::VectorXd::Zero(run.n);
  double d = 0.0;
  for (int s = 0; s < run.n; ++s) {
    const double v = run.v_cmd(s, axis);
    if (std::abs(v) > 1e-3) {
      const double nd = v > 0.0 ? 1.0 : -1.0;
      if (d != 0.0 && nd != d) reversals.push_back(s);
      d = nd;
    }
    dir[s] = d;
  }
}

namespace {

// The axes the program moves.
std::vector<int> moving_axes(const RunResiduals& r) {
  std::vector<int> moving;
  for (int a = 0; a < 3; ++a)
    if (r.moving[a]) moving.push_back(a);
  return moving;
}

// The largest case temperature change of either sensor over the run.
double temperature_range_c(const RunResiduals& r) {
  return std::max(r.temp_c.col(0).cwiseAbs().maxCoeff(), r.temp_c.col(1).cwiseAbs().maxCoeff());
}

AxisParam axis_param(std::string name, int axis, bool accel, Eigen::VectorXd input, double prior) {
  AxisParam p;
  p.name = std::move(name), p.axis = axis, p.accel = accel, p.input = std::move(input), p.prior_sigma = prior;
  return p;
}

// a_um: the driven acceleration, µm/s².
ParamGroup scale_group(const std::vector<int>& moving, const Eigen::MatrixXd& a_um) {
  ParamGroup gp{"scale", {}};
  for (int j : moving) gp.params.push_back(axis_param("scale_" + ax(j) + "_ppm", j, true, a_um.col(j) * 1e-6, 5e3));
  return gp;
}

ParamGroup cross_axis_group(const std::vector<int>& moving, const Eigen::MatrixXd& a_um) {
  ParamGroup gp{"cross_axis", {}};
  for (int j : moving)
    for (int i = 0; i < 3; ++i)
      if (i != j) gp.params.push_back(axis_param("E_" + ax(i) + ax(j) + "_ppm", i, true, a_um.col(j) * 1e-6, 2e4));
  return gp;
}

// a_drv: the driven acceleration, mm/s².
ParamGroup nonlinearity_group(const RunResiduals& r, const std::vector<int>& moving, const Eigen::MatrixXd& a_drv) {
  const double g = r.meta.site.g_mps2;
  ParamGroup gp{"nonlinearity", {}};
  for (int j : moving) {
    const Eigen::VectorXd ag = a_drv.col(j) / (1000.0 * g);  // in g
    const double sign =
        r.owner[j] == 0 ? -1.0 : 1.0;  // the table sees −a: its square term changes sign in head − table
    gp.params.push_back(
        axis_param("k2_" + ax(j) + "_1e-6_per_g", j, true, sign * ag.array().square().matrix() * g, 1e4));
    gp.params.push_back(axis_param("k3_" + ax(j) + "_1e-6_per_g2", j, true, ag.array().cube().matrix() * g, 1e4));
  }
  return gp;
}

// Against the set-point alone an axis' timing is its servo's (the base model's lag).
ParamGroup timing_group(const RunResiduals& r, const std::vector<int>& moving) {
  ParamGroup gp{"timing", {}};
  for (int j : moving)
    if (r.axis_reference[static_cast<std::size_t>(j)] != "cmd")
      gp.params.push_back(axis_param("timing_" + ax(j) + "_us", j, false, r.v_meas.col(j) * 1e-3, 300.0));
  return gp;
}

// ζ = ζ0 (1 + k |a|/g) (ch. 8.3.1): the PT2 drops (2ζ/ω0)·ȧ, so the extra damping
// drops −(2ζ0 k/(ω0 g))·|a|·ȧ = −(ζ0 k/(ω0 g))·d(a|a|)/dt of acceleration, i.e.
// −(ζ0 k/(ω0 g))·∫ a|a| dt of position — a plateau over a move's cruise that its
// deceleration takes back; on a circle, odd harmonics a constant 2ζ/ω0 does not have.
ParamGroup damping_amplitude_group(const RunResiduals& r, const std::vector<int>& moving,
                                   const Eigen::MatrixXd& a_drv) {
  const double g = r.meta.site.g_mps2;
  ParamGroup gp{"damping_amplitude", {}};
  for (int j : moving) {
    const dsp::SensorSpec& sp = r.meta.sensors[std::max(0, r.owner[j])];
    const double k = -sp.zeta / (2.0 * kPi * sp.f0_hz * g) * 1e6;  // µm per (m²/s³) of ∫a|a|dt
    Eigen::VectorXd col(r.n);
    double acc = 0.0, prev = 0.0;
    for (Eigen::Index s = 0; s < r.n; ++s) {
      const double a = a_drv(s, j) / 1000.0, cur = a * std::abs(a);
      if (s > 0) acc += 0.5 * (cur + prev) * (r.t_s[s] - r.t_s[s - 1]);
      prev = cur, col[s] = k * acc;
    }
    gp.params.push_back(axis_param("zeta_per_g_" + ax(j), j, false, col, 10.0));
  }
  return gp;
}

ParamGroup coriolis_group(const RunResiduals& r) {
  // An axis whose Coriolis acceleration stays below 0.1 µg (1 µm/s²) has no say in it.
  constexpr double kCoriolisFloorUmS2 = 1.0;
  // The Earth rate is known: the group is the site's prediction (gain 1, held there),
  // tested against the final model, not selected.
  constexpr double kCoriolisGainSigma = 1e-3;
  // Earth-rate Coriolis (3-6): the sensors measure 2ω×v on top of the motion; ω from the
  // site, one gain per axis it reaches (1: the site's prediction).
  const Eigen::Vector3d two_w = 2.0 * earth_rate_machine_radps(r.meta.site);
  Eigen::MatrixXd acc_um(r.n, 3);
  for (Eigen::Index s = 0; s < r.n; ++s)
    acc_um.row(s) = two_w.cross(Eigen::Vector3d(r.v_meas.row(s).transpose())).transpose() * 1000.0;  // mm/s → µm/s²
  ParamGroup gp{"coriolis", {}};
  for (int i = 0; i < 3; ++i)
    if (acc_um.col(i).cwiseAbs().maxCoeff() > kCoriolisFloorUmS2) {
      AxisParam cp = axis_param("coriolis_gain_" + ax(i), i, true, acc_um.col(i), kCoriolisGainSigma);
      cp.prior_mean = 1.0;  // the site's Earth rate
      gp.params.push_back(std::move(cp));
    }
  gp.known = true;
  return gp;
}

ParamGroup bias_drift_group(const RunResiduals& r) {
  const double g = r.meta.site.g_mps2;
  ParamGroup gp{"bias_drift", {}};
  for (int i = 0; i < 3; ++i)
    gp.params.push_back(axis_param("drift_" + ax(i) + "_ug_per_s", i, true, r.t_s * g, 100.0));
  return gp;
}

ParamGroup scale_temperature_group(const RunResiduals& r, const std::vector<int>& moving, const Eigen::MatrixXd& a_um) {
  const double g = r.meta.site.g_mps2;
  ParamGroup gp{"scale_temperature", {}};
  for (int j : moving)
    gp.params.push_back(axis_param("scale_tc_" + ax(j) + "_ppm_per_c", j, true,
                                   r.temp_c.col(std::max(0, r.owner[j])).cwiseProduct(a_um.col(j)) * 1e-6, 1e4));
  const Eigen::VectorXd mean_t = 0.5 * (r.temp_c.col(0) + r.temp_c.col(1));
  for (int i = 0; i < 3; ++i)
    gp.params.push_back(axis_param("bias_tc_" + ax(i) + "_ug_per_c", i, true, mean_t * g, 1e3));
  return gp;
}

}  // namespace

std::vector<ParamGroup> sensor_groups(const RunResiduals& run) {
  std::vector<ParamGroup> out;
  const std::vector<int> moving = moving_axes(run);
  if (moving.empty()) return out;
  const Eigen::MatrixXd a_drv = driven_acceleration(run);  // mm/s²
  const Eigen::MatrixXd a_um = a_drv * 1000.0;             // µm/s²
  out.push_back(scale_group(moving, a_um));
  out.push_back(cross_axis_group(moving, a_um));
  out.push_back(nonlinearity_group(run, moving, a_drv));
  if (ParamGroup gp = timing_group(run, moving); !gp.params.empty()) out.push_back(std::move(gp));
  out.push_back(damping_amplitude_group(run, moving, a_drv));
  if (ParamGroup gp = coriolis_group(run); !gp.params.empty()) out.push_back(std::move(gp));
  out.push_back(bias_drift_group(run));
  if (temperature_range_c(run) > 0.02) out.push_back(scale_temperature_group(run, moving, a_um));
  return out;
}

namespace {

double largest_abs(const std::map<std::string, double>& v) {
  double m = 0.0;
  for (const auto& [k, x] : v) m = std::max(m, std::abs(x));
  return m;
}

Attribution attribution(const char* name, double mag, double tol, const char* unit, const char* reg) {
  Attribution a;
  a.name = name, a.magnitude = mag, a.tolerance = tol, a.unit = unit, a.regressor = reg;
  return a;
}

// An effect sized by its largest parameter, the parameters as fitted.
Attribution sized_by_largest(const char* name, double tol, const char* unit, const char* reg,
                             const std::map<std::string, double>& v) {
  Attribution a = attribution(name, largest_abs(v), tol, unit, reg);
  a.params = v;
  return a;
}

// Per sensor: the largest rotation (mrad), symmetric term (ppm) and tilt (mrad) of its
// cross-axis terms, and whether it has a pair of moving axes.
struct CrossAxisParts {
  double rot_max[2] = {0.0, 0.0}, sym_max[2] = {0.0, 0.0}, tilt_max[2] = {0.0, 0.0};
  bool has_pair[2] = {false, false};
};

// Each pair of a sensor's moving axes split into rotation (antisymmetric) and cross
// coupling (symmetric); a moving axis' response on one that does not move is a tilt.
CrossAxisParts split_cross_axis(const RunResiduals& r, const std::map<std::string, double>& v, Attribution& mis,
                                Attribution& cross) {
  CrossAxisParts parts;
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 3; ++i) {
      if (i == j || !r.moving[j] || r.owner[j] < 0) continue;
      const int s = r.owner[j];
      const double eij = get(v, "E_" + ax(i) + ax(j) + "_ppm");
      if (r.moving[i] && r.owner[i] == s) {
        if (i < j) continue;
        const double eji = get(v, "E_" + ax(j) + ax(i) + "_ppm");
        const double rot = 0.5 * (eij - eji) / 1000.0, sym = 0.5 * (eij + eji);
        mis.params["rotation_" + ax(j) + ax(i) + "_mrad"] = rot;
        cross.params["cross_" + ax(j) + ax(i) + "_ppm"] = sym;
        parts.rot_max[s] = std::max(parts.rot_max[s], std::abs(rot));
        parts.sym_max[s] = std::max(parts.sym_max[s], std::abs(sym));
        parts.has_pair[s] = true;
      } else {
        mis.params["tilt_" + ax(j) + "_into_" + ax(i) + "_mrad"] = eij / 1000.0;
        parts.tilt_max[s] = std::max(parts.tilt_max[s], std::abs(eij) / 1000.0);
      }
    }
  return parts;
}

// Two moving axes of one sensor: the antisymmetric part of their pair is a rotation of
// the mounting, the symmetric part axes that are not square to each other or respond
// across (cross coupling) — a rotation cannot make it. A sensor whose pairs show cross
// coupling is named for it alone (a general cross-axis matrix explains the rotation
// too), unless the rotation clearly dominates (3×); a moving axis' response on an axis
// that does not move (a tilt) goes with what its sensor's pairs show, mounting when
// the sensor has no pair (the two are one effect then, and the evidence says so).
std::vector<Attribution> attribute_cross_axis(const RunResiduals& r, const std::map<std::string, double>& v) {
  Attribution mis = attribution("sensor.misalignment", 0.0, 1.0, "mrad",
                                "the other axes' doubly integrated acceleration, antisymmetric");
  Attribution cross = attribution("sensor.cross_coupling", 0.0, 500.0, "ppm",
                                  "the other axes' doubly integrated acceleration, symmetric");
  const CrossAxisParts p = split_cross_axis(r, v, mis, cross);
  for (int s = 0; s < 2; ++s) {
    const bool crossed = p.has_pair[s] && p.sym_max[s] > cross.tolerance && p.rot_max[s] < 3.0 * p.sym_max[s] * 1e-3;
    if (crossed) {
      // Rotation and tilts are cross-axis terms of this sensor too: sized in ppm with it.
      cross.magnitude = std::max({cross.magnitude, p.sym_max[s], p.rot_max[s] * 1000.0, p.tilt_max[s] * 1000.0});
      mis.params[std::string("included_in_cross_coupling_") + (s == 0 ? "table" : "head")] = 1.0;
    } else {
      cross.magnitude = std::max(cross.magnitude, p.sym_max[s]);
      mis.magnitude = std::max({mis.magnitude, p.rot_max[s], p.tilt_max[s]});
    }
  }
  if (!p.has_pair[0] && !p.has_pair[1])
    mis.regressor += " (one moving axis per sensor: mounting and cross coupling are one effect here)";
  return {mis, cross};
}

// Per sensor the common shift (2ζ/ω0, or a delay); against the set-point only, what the
// axes differ by is their position loops'.
Attribution attribute_timing(const RunResiduals& r, const std::map<std::string, double>& v) {
  Attribution dyn = attribution("sensor.dynamics", 0.0, 15.0, "us", "the velocity (2ζ/ω0 · v, (6-38))");
  for (int s = 0; s < 2; ++s) {
    double sum = 0.0;
    int n = 0;
    // Against the set-point alone the axis' servo lag is unknown: its timing says
    // nothing about the sensor.
    for (int j = 0; j < 3; ++j)
      if (r.moving[j] && r.owner[j] == s && r.axis_reference[static_cast<std::size_t>(j)] != "cmd")
        sum += get(v, "timing_" + ax(j) + "_us"), ++n;
    if (n == 0) continue;
    const double mean = sum / n;
    dyn.params[std::string("damping_term_error_us_") + (s == 0 ? "table" : "head")] = mean;
    dyn.magnitude = std::max(dyn.magnitude, std::abs(mean));
  }
  return dyn;
}

// The site's prediction, held at gain 1: its size is the peak Coriolis acceleration of
// the motion. Within one move it acts like a bias; a run shows it where it changes sign
// with the direction of motion — the filter's likelihood decides that, not its size.
Attribution attribute_coriolis(const RunResiduals& r, const std::map<std::string, double>& v) {
  const Eigen::Vector3d two_w = 2.0 * earth_rate_machine_radps(r.meta.site);
  double peak_ug = 0.0;
  for (int i = 0; i < 3; ++i) {
    if (v.find("coriolis_gain_" + ax(i)) == v.end()) continue;
    for (Eigen::Index s2 = 0; s2 < r.n; ++s2)
      peak_ug = std::max(peak_ug, std::abs(two_w.cross(Eigen::Vector3d(r.v_meas.row(s2).transpose()))[i]) * 1e-3 /
                                      (r.meta.site.g_mps2 * 1e-6));
  }
  Attribution a =
      attribution("site.coriolis", peak_ug, 1.0, "ug", "the Earth rate's 2ω×v of the motion (3-6), from the site");
  a.params = v;
  a.params["peak_ug"] = peak_ug;
  return a;
}

Attribution attribute_scale_temperature(const RunResiduals& r, const std::map<std::string, double>& v) {
  const double range = temperature_range_c(r);
  double m = 0.0;
  for (const auto& [k, x] : v) m = std::max(m, std::abs(x) * range * (k.rfind("bias", 0) == 0 ? 50.0 : 1.0));
  Attribution a = attribution("sensor.scale_temperature", m, 50.0, "ppm over the run (1 ug as 50 ppm)",
                              "the temperature change times the acceleration, and alone");
  a.params = v;
  a.params["temperature_change_c"] = range;
  return a;
}

}  // namespace

std::vector<Attribution> attribute_sensor_group(const RunResiduals& run, const std::string& group,
                                                const std::map<std::string, double>& values) {
  if (group == "scale")
    return {
        sized_by_largest("sensor.scale", 1000.0, "ppm", "the doubly integrated acceleration along the axis", values)};
  if (group == "cross_axis") return attribute_cross_axis(run, values);
  if (group == "nonlinearity")
    return {sized_by_largest("sensor.nonlinearity", 200.0, "1e-6/g",
                             "the doubly integrated square and cube of the acceleration", values)};
  if (group == "timing") return {attribute_timing(run, values)};
  if (group == "damping_amplitude")
    return {sized_by_largest("sensor.damping_amplitude", 0.2, "1/g",
                             "the integral of a·|a| (damping growing with the acceleration)", values)};
  if (group == "coriolis") return {attribute_coriolis(run, values)};
  if (group == "bias_drift")
    return {
        sized_by_largest("sensor.bias_drift", 0.3, "ug/s", "the doubly integrated time (a linear bias drift)", values)};
  if (group == "scale_temperature") return {attribute_scale_temperature(run, values)};
  return {};
}

namespace {

// Lost motion as a play operator on the commanded position: after a reversal the slide
// stands while the command crosses the play, so near a circle's quadrant, where the
// axis reverses slowly, the play is taken up over milliseconds, not in a step. The
// play's width shapes the column; the fitted coefficient is its size.
EffectModel backlash_effect(const RunResiduals& r, const Eigen::MatrixXd& hint, const std::vector<int>& moving,
                            const std::vector<int> (&rev)[3]) {
  EffectModel e = effect("machine.backlash");
  for (int a : moving) {
    if (rev[a].empty()) continue;
    Eigen::VectorXd best;
    double best_c = -1.0;
    for (double play_um : {0.5, 1.0, 2.0, 3.0, 4.0, 6.0, 8.0, 11.0, 15.0, 20.0, 30.0}) {
      const Eigen::VectorXd col = play_operator_column(r.cmd.col(a), play_um);
      const double c = hint_corr(hint, col, a);
      if (c > best_c) best_c = c, best = col;
    }
    e.params.push_back("backlash_" + ax(a) + "_um"), e.columns.push_back(on_axis(best, a));
  }
  e.magnitude = max_abs, e.tolerance = 1.0, e.unit = "um",
  e.regressor = "half the play against the direction of the last motion";
  return e;
}

// Friction holds the slide as the axis reverses: the lag grows from zero like t²
// (position and velocity continuous), peaks at tau with the given size, decays.
Eigen::VectorXd reversal_spike_column(const RunResiduals& r, const Eigen::VectorXd& dir, const std::vector<int>& rev,
                                      double tau_ms) {
  const Eigen::Index n = r.n;
  Eigen::VectorXd col = Eigen::VectorXd::Zero(n);
  for (int s0 : rev) {
    const double sign = -dir[s0];  // the slide lags behind its new direction
    for (Eigen::Index s = s0; s < n; ++s) {
      const double t = (r.t_s[s] - r.t_s[s0]) / (tau_ms * 1e-3);
      if (t > 12.0) break;
      col[s] += sign * t * t * std::exp(2.0 * (1.0 - t));
    }
  }
  return col;
}

EffectModel reversal_spike_effect(const RunResiduals& r, const Eigen::MatrixXd& hint, const std::vector<int>& moving,
                                  const Eigen::VectorXd (&dir)[3], const std::vector<int> (&rev)[3]) {
  EffectModel e = effect("machine.reversal_spike");
  for (int a : moving) {
    if (rev[a].empty()) continue;
    Eigen::VectorXd best;
    double best_c = -1.0, best_tau = 0.0;
    for (double tau_ms : {5.0, 8.0, 12.0, 16.0, 20.0, 25.0, 30.0, 40.0, 50.0}) {
      Eigen::VectorXd col = reversal_spike_column(r, dir[a], rev[a], tau_ms);
      const double c = hint_corr(hint, col, a);
      if (c > best_c) best_c = c, best = col, best_tau = tau_ms;
    }
    e.params.push_back("spike_" + ax(a) + "_um_tau_" + std::to_string(static_cast<int>(best_tau)) + "ms");
    e.columns.push_back(on_axis(best, a));
  }
  e.magnitude = max_abs, e.tolerance = 1.0, e.unit = "um", e.regressor = "a lag peaking tau after each reversal";
  return e;
}

// The common lag is the base model's (machine_base_columns); this is what axes differ by.
EffectModel servo_mismatch_effect(const std::vector<int>& moving, const LagColumns& lag) {
  EffectModel e = effect("machine.servo_mismatch");
  for (std::size_t i = 1; i < moving.size(); ++i) {
    const int a = moving[i];
    e.params.push_back("lag_" + ax(a) + "_minus_" + ax(moving[0]) + "_ms"),
        e.columns.push_back(on_axis(lag.velocity.col(a), a));
  }
  e.magnitude = max_abs;
  e.tolerance = 0.05, e.unit = "ms", e.regressor = "an axis' commanded velocity (lag) beyond the others'";
  return e;
}

EffectModel scale_mismatch_effect(const RunResiduals& r, const std::vector<int>& moving) {
  EffectModel e = effect("machine.scale_mismatch");
  for (int a : moving)
    e.params.push_back("scale_" + ax(a) + "_ppm"),
        e.columns.push_back(on_axis((r.cmd.col(a).array() - r.cmd.col(a).mean()).matrix() * 1e-3, a));
  e.magnitude = [](const Eigen::VectorXd& p) { return p.size() > 1 ? p.maxCoeff() - p.minCoeff() : std::abs(p[0]); };
  e.tolerance = 10.0, e.unit = "ppm", e.regressor = "the commanded position along the axis";
  return e;
}

EffectModel squareness_effect(const RunResiduals& r, const std::vector<int>& moving) {
  const Eigen::Index n = r.n;
  EffectModel e = effect("machine.squareness");
  for (std::size_t p = 0; p < moving.size(); ++p)
    for (std::size_t q = p + 1; q < moving.size(); ++q) {
      const int i = moving[p], j = moving[q];
      e.params.push_back("squareness_" + ax(i) + ax(j) + "_urad");
      Eigen::MatrixXd c = Eigen::MatrixXd::Zero(n, 3);
      c.col(i) = -0.5e-3 * (r.cmd.col(j).array() - r.cmd.col(j).mean()).matrix();
      c.col(j) = -0.5e-3 * (r.cmd.col(i).array() - r.cmd.col(i).mean()).matrix();
      e.columns.push_back(c);
    }
  e.magnitude = max_abs, e.tolerance = 10.0, e.unit = "urad",
  e.regressor = "each axis' commanded position on the other";
  return e;
}

// The ball-screw pitch (of a few standard ones, at most 2/3 of the travel) whose sine and
// cosine the hint follows best; 0 when none fits in the travel.
double cyclic_pitch_mm(const RunResiduals& r, const Eigen::MatrixXd& hint, int a) {
  const double span = r.cmd.col(a).maxCoeff() - r.cmd.col(a).minCoeff();
  double best_c = -1.0, best_p = 0.0;
  for (double pitch : {1.0, 2.0, 2.5, 4.0, 5.0, 6.0, 8.0, 10.0, 12.0, 16.0, 20.0}) {
    if (pitch > span / 1.5) continue;
    const Eigen::VectorXd sn = (2.0 * kPi * r.cmd.col(a).array() / pitch).sin().matrix();
    const Eigen::VectorXd cs = (2.0 * kPi * r.cmd.col(a).array() / pitch).cos().matrix();
    const double c = std::hypot(hint_corr(hint, sn, a), hint_corr(hint, cs, a));
    if (c > best_c) best_c = c, best_p = pitch;
  }
  return best_p;
}

EffectModel cyclic_error_effect(const RunResiduals& r, const Eigen::MatrixXd& hint, const std::vector<int>& moving) {
  EffectModel e = effect("machine.cyclic_error");
  for (int a : moving) {
    const double best_p = cyclic_pitch_mm(r, hint, a);
    if (best_p <= 0.0) continue;
    char name[64];
    std::snprintf(name, sizeof name, "cyclic_%s_pitch_%gmm", kAxisName[a], best_p);
    e.params.push_back(std::string(name) + "_sin_um");
    e.columns.push_back(on_axis((2.0 * kPi * r.cmd.col(a).array() / best_p).sin().matrix(), a));
    e.params.push_back(std::string(name) + "_cos_um");
    e.columns.push_back(on_axis((2.0 * kPi * r.cmd.col(a).array() / best_p).cos().matrix(), a));
  }
  e.magnitude = [](const Eigen::VectorXd& p) {
    double m = 0.0;
    for (Eigen::Index i = 0; i + 1 < p.size(); i += 2) m = std::max(m, std::hypot(p[i], p[i + 1]));
    return m;
  };
  e.tolerance = 0.5, e.unit = "um", e.regressor = "a sine of the commanded position (ball-screw pitch)";
  return e;
}

EffectModel straightness_effect(const RunResiduals& r, const std::vector<int>& moving) {
  EffectModel e = effect("machine.straightness");
  for (int i : moving) {
    const double lo = r.cmd.col(i).minCoeff(), hi = r.cmd.col(i).maxCoeff();
    if (hi - lo < 5.0) continue;
    const Eigen::VectorXd u = ((2.0 * r.cmd.col(i).array() - lo - hi) / (hi - lo)).matrix();
    Eigen::VectorXd bow = (1.0 - u.array().square()).matrix();
    bow.array() -= bow.mean();
    for (int j = 0; j < 3; ++j)
      if (j != i) e.params.push_back("bow_of_" + ax(i) + "_in_" + ax(j) + "_um"), e.columns.push_back(on_axis(bow, j));
  }
  e.magnitude = max_abs, e.tolerance = 1.0, e.unit = "um", e.regressor = "a bow over the axis' travel, sideways";
  return e;
}

// An effect with columns on this run joins the list.
void add_if_any(std::vector<EffectModel>& out, EffectModel e) {
  if (!e.params.empty()) out.push_back(std::move(e));
}

}  // namespace

std::vector<EffectModel> machine_effects(const RunResiduals& run, const Eigen::MatrixXd& hint, const LagColumns& lag) {
  std::vector<EffectModel> out;
  const std::vector<int> moving = moving_axes(run);
  if (moving.empty()) return out;
  Eigen::VectorXd dir[3];
  std::vector<int> rev[3];
  for (int a : moving) axis_directions(run, a, dir[a], rev[a]);
  add_if_any(out, backlash_effect(run, hint, moving, rev));
  add_if_any(out, reversal_spike_effect(run, hint, moving, dir, rev));
  if (moving.size() >= 2) out.push_back(servo_mismatch_effect(moving, lag));
  out.push_back(scale_mismatch_effect(run, moving));
  add_if_any(out, squareness_effect(run, moving));
  add_if_any(out, cyclic_error_effect(run, hint, moving));
  add_if_any(out, straightness_effect(run, moving));
  return out;
}

LagColumns common_lag_columns(const RunResiduals& run, const std::array<double, 3>& tau_s_per_axis) {
  LagColumns c;
  c.tau_s = tau_s_per_axis;
  c.velocity = Eigen::MatrixXd::Zero(run.n, 3), c.acceleration = Eigen::MatrixXd::Zero(run.n, 3);
  for (int a = 0; a < 3; ++a) {
    if (!run.moving[a]) continue;
    const double tau_s = tau_s_per_axis[static_cast<std::size_t>(a)];
    double v = 0.0, acc = 0.0;
    for (Eigen::Index s = 0; s < run.n; ++s) {
      const double h = s > 0 ? run.t_s[s] - run.t_s[s - 1] : 0.0;
      const double k = tau_s > 0.0 ? 1.0 - std::exp(-h / tau_s) : 1.0;  // exact for a held input
      v += (run.v_cmd(s, a) - v) * (s == 0 ? 1.0 : k), acc += (run.a_cmd(s, a) - acc) * (s == 0 ? 1.0 : k);
      c.velocity(s, a) = -v;              // mm/s × ms = µm
      c.acceleration(s, a) = acc * 1e-3;  // mm/s² × ms² = 1e-3 µm
    }
  }
  return c;
}

namespace {
// Per axis: offset, LP(v) and LP(a) by least squares on the rows where the hint is known;
// the residual of those rows (none below 20 rows).
std::pair<std::vector<Eigen::Index>, Eigen::VectorXd> lag_fit_residual(const Eigen::MatrixXd& hint, const LagColumns& c,
                                                                       int a) {
  std::vector<Eigen::Index> rows;
  for (Eigen::Index s = 0; s < hint.rows(); ++s)
    if (std::isfinite(hint(s, a))) rows.push_back(s);
  if (rows.size() < 20) return {};
  Eigen::MatrixXd x(static_cast<Eigen::Index>(rows.size()), 3);
  Eigen::VectorXd y(static_cast<Eigen::Index>(rows.size()));
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const auto ii = static_cast<Eigen::Index>(i);
    x(ii, 0) = 1.0, x(ii, 1) = c.velocity(rows[i], a), x(ii, 2) = c.acceleration(rows[i], a), y[ii] = hint(rows[i], a);
  }
  Eigen::VectorXd e = y - x * x.colPivHouseholderQr().solve(y);
  return {std::move(rows), std::move(e)};
}
}  // namespace

Eigen::MatrixXd without_lag(const Eigen::MatrixXd& hint, const LagColumns& lag) {
  Eigen::MatrixXd out = hint;
  for (int a = 0; a < 3; ++a) {
    if (lag.velocity.col(a).cwiseAbs().maxCoeff() <= 0.0) continue;
    const auto [rows, e] = lag_fit_residual(hint, lag, a);
    for (std::size_t i = 0; i < rows.size(); ++i) out(rows[i], a) = e[static_cast<Eigen::Index>(i)];
  }
  return out;
}

std::array<double, 3> loop_time_constant_s(const RunResiduals& run, const Eigen::MatrixXd& hint) {
  // Per axis: each axis' loop has its own gain (kv) and so its own time constant; a common
  // one leaves τ·a-shaped residuals that look like scale mismatch on a circle.
  std::array<double, 3> best_tau{};
  for (int a = 0; a < 3; ++a) {
    if (!run.moving[a]) continue;
    auto rss_at = [&](double tau_s) {
      std::array<double, 3> t{};
      t[static_cast<std::size_t>(a)] = tau_s;
      return lag_fit_residual(hint, common_lag_columns(run, t), a).second.squaredNorm();
    };
    double best_rss = kInf, tau = 0.0;
    for (double tau_ms = 0.0; tau_ms <= 100.0; tau_ms += tau_ms < 60.0 ? 2.0 : 10.0)
      if (const double q = rss_at(tau_ms * 1e-3); q < best_rss) best_rss = q, tau = tau_ms * 1e-3;
    // Golden-section refinement within one grid step either side.
    double lo = std::max(0.0, tau - 2e-3), hi = tau + 2e-3;
    constexpr double kGolden = 0.6180339887498949;
    for (int it = 0; it < 12; ++it) {
      const double m1 = hi - kGolden * (hi - lo), m2 = lo + kGolden * (hi - lo);
      (rss_at(m1) < rss_at(m2) ? hi : lo) = (rss_at(m1) < rss_at(m2) ? m2 : m1);
    }
    best_tau[static_cast<std::size_t>(a)] = 0.5 * (lo + hi);
  }
  return best_tau;
}

std::vector<AxisParam> servo_base(const RunResiduals& run, const LagColumns& lag) {
  std::vector<AxisParam> out;
  for (int a = 0; a < 3; ++a) {
    if (!run.moving[a] || run.axis_reference[static_cast<std::size_t>(a)] != "cmd") continue;
    AxisParam p;
    p.axis = a, p.accel = false;
    p.name = "servo_lag_" + ax(a) + "_ms", p.input = lag.velocity.col(a), p.prior_sigma = 10.0;
    out.push_back(p);
    p.name = "servo_acc_" + ax(a) + "_ms2", p.input = lag.acceleration.col(a), p.prior_sigma = 1e3;
    out.push_back(p);
  }
  return out;
}

ParamGroup as_group(const EffectModel& e, const std::array<bool, 3>& axes) {
  ParamGroup g{e.name, {}};
  for (std::size_t p = 0; p < e.params.size(); ++p) {
    int used = 0;
    for (int a = 0; a < 3; ++a)
      used += axes[static_cast<std::size_t>(a)] && e.columns[p].col(a).cwiseAbs().maxCoeff() > 0.0;
    for (int a = 0; a < 3; ++a) {
      if (!axes[static_cast<std::size_t>(a)] || e.columns[p].col(a).cwiseAbs().maxCoeff() <= 0.0) continue;
      AxisParam ap;
      ap.name = used > 1 ? e.params[p] + "@" + ax(a) : e.params[p];
      ap.axis = a, ap.accel = false, ap.input = e.columns[p].col(a), ap.prior_sigma = 1e3;
      g.params.push_back(ap);
    }
  }
  return g;
}

}  // namespace eical::dsp::model
