#include "dsp/identify/sensor_identification.hpp"

#include "dsp/core/axes.hpp"
#include "dsp/core/error.hpp"
#include "dsp/core/interpolate.hpp"
#include "dsp/identify/augmented_filter.hpp"
#include "dsp/identify/axis_observations.hpp"
#include "dsp/identify/delay_estimate.hpp"
#include "dsp/supports/psd_nonlinearity.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

namespace eical::dsp::identify {
namespace {

// Which sensor moves machine axis j: 0 table, 1 head, −1 neither.
int owner(const RunMeta& meta, int j) { return axis_owner(meta.machine, j); }

struct AxisFit {
  Layout layout;
  Eigen::VectorXd theta, sigma;
  Eigen::MatrixXd cov;  // of the parameters
  // The position observations' mean normalised innovation² (1 when the filter's model of
  // the noise and the sensors holds).
  double position_nis = 0.0;
};

struct PassResult {
  AxisFit axis[3];
  bool moved[3] = {false, false, false};
  double psd_rms_um = 0.0, rest_rms_um = 0.0;
  std::size_t psd_obs = 0, rest_obs = 0, standstills = 0;
  Measurement m;
};

double rms_about_mean(const std::vector<double>& v) {
  if (v.empty()) return 0.0;
  double mean = 0.0;
  for (double x : v) mean += x;
  mean /= static_cast<double>(v.size());
  double ss = 0.0;
  for (double x : v) ss += (x - mean) * (x - mean);
  return std::sqrt(ss / static_cast<double>(v.size()));
}

// The pipeline's integration with the data-sheet model as `meta` has it, the raw trace
// kept; no PSD fixes and no smoother: the filters below fit what it leaves.
Measurement integrate_raw(const Run& run, const RunMeta& meta, fusion::ErrorModel& model) {
  PipelineConfig cfg = pipeline_config(meta, run.frames.size());
  cfg.keep_raw = true;
  cfg.cupt = false;
  cfg.smooth = false;
  model = cfg.fusion;
  Pipeline pipe(cfg);
  for (const auto& f : run.frames) pipe.step(f);
  return pipe.finish();
}

using Standstills = std::vector<std::pair<std::size_t, std::size_t>>;  // first, last sample

// The standstills of the raw trace (runs of rest samples); throws unless there is motion
// with at least two of them.
Standstills standstills_of(const Measurement& m) {
  const RawTrace& raw = m.raw;
  if (raw.empty())
    throw InputError("identify: the run has no motion to identify from (" +
                     std::string(m.flags.empty() ? "" : flag_text(m.flags.front())) + ")");
  const std::size_t n = raw.pos_mm.size();
  const auto& flags = raw.schedule.flags;
  if (flags.size() != n) throw InputError("identify: the support schedule does not cover the trace");
  Standstills rests;
  for (std::size_t k = 0; k < n; ++k) {
    if (!(flags[k] & fusion::schedule_flag::rest)) continue;
    if (rests.empty() || rests.back().second + 1 != k)
      rests.push_back({k, k});
    else
      rests.back().second = k;
  }
  if (rests.empty()) throw InputError("identify: no standstill in the run (the program must rest between its moves)");
  if (rests.size() < 2)
    throw InputError(
        "identify: the run rests only once in its motion: the set-point at the standstills between moves is what ties "
        "the scale "
        "down (run the identification program, eical gen-nc identify)");
  return rests;
}

// The axes whose set-point spans more than 0.5 mm and that a sensor moves.
void moved_axes(const Measurement& m, const RunMeta& meta, bool moved[3]) {
  for (int j = 0; j < 3; ++j) {
    double lo = 1e300, hi = -1e300;
    for (const auto& c : m.cmd_mm) lo = std::min(lo, c[j]), hi = std::max(hi, c[j]);
    moved[j] = hi - lo > 0.5 && owner(meta, j) >= 0;
  }
}

// What every axis' filter of a pass reads.
struct PassInputs {
  const Run& run;
  const RunMeta& meta;
  const IdentifyOptions& o;
  const Measurement& m;
  const fusion::ErrorModel& model;
  const Standstills& rests;
};

// One axis' filter run over the trace, sample by sample: the prediction with the
// acceleration gains of the E terms, then the observations of the sample in a fixed order
// (the start, ZUPT, ringing standstills' velocity means, then the set-point at mid
// standstill and the PSD fixes, or the reference).
class AxisPass {
 public:
  AxisPass(const PassInputs& in, int axis, const Layout& layout, AugmentedFilter& f)
      : in_(in),
        i_(axis),
        L_(layout),
        f_(f),
        strip_count_(in.meta.psd.size(), 0),
        g_(Eigen::VectorXd::Zero(layout.count)),
        h_(Eigen::RowVectorXd::Zero(3 + layout.count)) {}

  void sample(std::size_t k) {
    if (k > 0) predict(k);
    const RawTrace& raw = in_.m.raw;
    const double x_um = raw.pos_mm[k][i_] * 1000.0, v_um_s = raw.vel_mm_s[k][i_] * 1000.0;
    if (k == 0 && !in_.o.against_reference) {  // the integration starts at the set-point: δx0 = −(offset there)
      observe::start_row(L_, h_);
      f_.update(h_, 0.0, 1e-3);
    }
    observe_standstill_velocity(k, v_um_s);
    if (!in_.o.against_reference) {
      observe_rest_setpoint(k, x_um);
      observe_psd_fixes(k, x_um, v_um_s);
    } else if (in_.run.channels.ref[i_] && k % static_cast<std::size_t>(std::max(1, in_.o.reference_every)) == 0) {
      observe_reference(k, x_um, v_um_s);
    }
  }

  std::vector<double> psd_res, rest_res;  // what the observations left, before their update
  std::size_t psd_obs = 0, rest_obs = 0;
  double nis_sum = 0.0;  // of the set-point and PSD observations

 private:
  // The step from k − 1 to k: E's gains the mean acceleration over it; the direction of the
  // axis' last move (backlash).
  void predict(std::size_t k) {
    const RawTrace& raw = in_.m.raw;
    const Eigen::Vector3d a_now = (raw.head_mps2[k] - raw.table_mps2[k]) * 1e6;  // µm/s²
    const Eigen::Vector3d a_prev = (raw.head_mps2[k - 1] - raw.table_mps2[k - 1]) * 1e6;
    for (int j = 0; j < 3; ++j)
      if (L_.e[j] >= 0) g_[L_.e[j]] = 0.5 * (a_now[j] + a_prev[j]);
    const double h = static_cast<double>(in_.m.sample_index[k] - in_.m.sample_index[k - 1]) / in_.m.fs_hz;
    f_.predict(h, g_, (raw.schedule.flags[k] & fusion::schedule_flag::move_start) != 0);
    const double dc = in_.m.cmd_mm[k][i_] - in_.m.cmd_mm[k - 1][i_];
    if (std::abs(dc) > 1e-9) dir_ = dc > 0.0 ? 1.0 : -1.0;
  }

  // ZUPT at a quiet standstill; the velocity means of a ringing one.
  void observe_standstill_velocity(std::size_t k, double v_um_s) {
    namespace sf = fusion::schedule_flag;
    const auto& sched = in_.m.raw.schedule;
    const auto& zs = sched.zupt_sigma_um_s;
    const double zupt_sigma = in_.model.zupt_sigma_um_s;
    if ((sched.flags[k] & sf::rest) && !(sched.flags[k] & sf::invalid) && (k >= zs.size() || zs[k] == 0.0F)) {
      observe::zupt_row(h_);
      f_.update(h_, v_um_s, zupt_sigma);
    }
    const auto& means = sched.velocity_means;
    for (; next_mean_ < means.size() && means[next_mean_].k <= k; ++next_mean_) {
      const fusion::VelocityMean& vm = means[next_mean_];
      if (vm.k != k) continue;
      observe::velocity_mean_row(vm.lag_s, h_);
      f_.update(h_, vm.mean_um_s[i_], std::max(zupt_sigma, vm.sigma_um_s));
    }
  }

  // The set-point at the middle of each standstill.
  void observe_rest_setpoint(std::size_t k, double x_um) {
    const Standstills& rests = in_.rests;
    while (next_rest_ < rests.size() && (rests[next_rest_].first + rests[next_rest_].second) / 2 < k) ++next_rest_;
    if (next_rest_ < rests.size() && (rests[next_rest_].first + rests[next_rest_].second) / 2 == k) {
      observe::rest_row(L_, dir_, h_);
      const double z = x_um - in_.m.cmd_mm[k][i_] * 1000.0;
      rest_res.push_back(z);
      nis_sum += f_.update(h_, z, in_.o.rest_sigma_um);
      ++rest_obs;
    }
  }

  // Every psd_every-th lit sample of each strip measuring this axis.
  void observe_psd_fixes(std::size_t k, double x_um, double v_um_s) {
    const auto& fixes = in_.m.raw.schedule.fixes;
    const int n_strips = static_cast<int>(in_.meta.psd.size());
    for (; next_fix_ < fixes.size() && fixes[next_fix_].k <= k; ++next_fix_) {
      const fusion::PositionFix& fx = fixes[next_fix_];
      if (fx.k != k || fx.axis != i_ || fx.strip < 0 || fx.strip >= n_strips) continue;
      if (strip_count_[static_cast<std::size_t>(fx.strip)]++ % std::max(1, in_.o.psd_every) != 0) continue;
      const double shape_um =
          supports::psd_nonlinearity_shape_um(in_.meta.psd[static_cast<std::size_t>(fx.strip)], fx.position_um);
      observe::psd_row(L_, v_um_s, fx.strip, shape_um, h_);
      const double z = x_um - fx.position_um;
      psd_res.push_back(z);
      nis_sum += f_.update(h_, z, std::hypot(fx.sigma_um, in_.model.psd_floor_um));
      ++psd_obs;
    }
  }

  // The reference instrument, which the sensors see k − d samples late.
  void observe_reference(std::size_t k, double x_um, double v_um_s) {
    const double pos = static_cast<double>(k) - in_.meta.acquisition.daq_group_delay_samples;  // sensors see k − d
    const double ref = interpolate_at(in_.m.ref_mm, pos, i_);
    if (std::isfinite(ref) && pos >= 0.0) {
      observe::reference_row(L_, v_um_s, h_);
      nis_sum += f_.update(h_, x_um - ref * 1000.0, in_.o.reference_sigma_um);
      ++psd_obs;
    }
  }

  const PassInputs& in_;
  const int i_;
  const Layout& L_;
  AugmentedFilter& f_;
  double dir_ = 0.0;
  std::size_t next_rest_ = 0, next_fix_ = 0, next_mean_ = 0;
  std::vector<int> strip_count_;
  Eigen::VectorXd g_;
  Eigen::RowVectorXd h_;  // the observation's row
};

// One axis' augmented filter over the whole trace: its parameters and their covariance into
// r.axis[i], its observations into r's counts and RMS.
void fit_axis(const PassInputs& in, int i, PassResult& r) {
  const AxisPrior prior = axis_prior(i, r.moved, in.meta.psd, in.o.against_reference);
  const int np = prior.layout.count;
  AugmentedFilter f(in.model, Eigen::Vector3d(kPriorOffsetUm, 1.0, 20.0),
                    Eigen::Map<const Eigen::VectorXd>(prior.sigma.data(), np));
  AxisPass pass(in, i, prior.layout, f);
  const std::size_t n = in.m.raw.pos_mm.size();
  for (std::size_t k = 0; k < n; ++k) pass.sample(k);
  AxisFit& fit = r.axis[i];
  fit.layout = prior.layout;
  fit.theta = f.state().tail(np);
  fit.sigma.resize(np);
  for (int p = 0; p < np; ++p) fit.sigma[p] = f.parameter_sigma(p);
  fit.cov = f.covariance().bottomRightCorner(np, np);
  const std::size_t position_obs = pass.psd_obs + pass.rest_obs;
  fit.position_nis = position_obs > 0 ? pass.nis_sum / static_cast<double>(position_obs) : 0.0;
  r.psd_obs += pass.psd_obs, r.rest_obs += pass.rest_obs;
  // RMS of what the observations left about their offsets, before this pass's fit.
  r.psd_rms_um = std::max(r.psd_rms_um, rms_about_mean(pass.psd_res));
  r.rest_rms_um = std::max(r.rest_rms_um, rms_about_mean(pass.rest_res));
}

// One identification pass: the integration with the sensors of `meta`, then each axis'
// filter over it.
PassResult fit_pass(const Run& run, const RunMeta& meta, const IdentifyOptions& o) {
  PassResult r;
  fusion::ErrorModel model;
  r.m = integrate_raw(run, meta, model);
  const Standstills rests = standstills_of(r.m);
  r.standstills = rests.size();
  moved_axes(r.m, meta, r.moved);
  const PassInputs in{run, meta, o, r.m, model, rests};
  for (int i = 0; i < 3; ++i) fit_axis(in, i, r);
  return r;
}

// How well the pipeline with these sensors — ZUPT and smoother, no PSD fixes — agrees with
// the PSD readings (it did not use them) and with the set-point at the standstills:
// RMS about each strip's (each axis') own mean.
struct Agreement {
  double psd_rms_um = 0.0, rest_rms_um = 0.0;
};

Agreement agreement(const Run& run, const RunMeta& meta) {
  PipelineConfig cfg = pipeline_config(meta, run.frames.size());
  cfg.keep_raw = true;
  cfg.cupt = false;
  Pipeline pipe(cfg);
  for (const auto& f : run.frames) pipe.step(f);
  const Measurement m = pipe.finish();
  Agreement a;
  if (m.raw.empty()) return a;
  const double d = meta.acquisition.daq_group_delay_samples;
  std::vector<std::vector<double>> per_strip(meta.psd.size());
  for (const auto& fx : m.raw.schedule.fixes) {
    if (fx.strip < 0 || static_cast<std::size_t>(fx.strip) >= per_strip.size()) continue;
    const double pos =
        interpolate_at(m.pos_mm, static_cast<double>(fx.k) - d, fx.axis);  // the trace is on the set-point's time
    per_strip[static_cast<std::size_t>(fx.strip)].push_back(pos * 1000.0 - fx.position_um);
  }
  double ss = 0.0;
  std::size_t n = 0;
  for (const auto& v : per_strip) {
    const double r = rms_about_mean(v);
    ss += r * r * static_cast<double>(v.size()), n += v.size();
  }
  a.psd_rms_um = n > 0 ? std::sqrt(ss / static_cast<double>(n)) : 0.0;
  // Standstill mids (sensor time) → the trace at k − d.
  namespace sf = fusion::schedule_flag;
  const auto& flags = m.raw.schedule.flags;
  std::vector<double> per_axis[3];
  for (std::size_t k = 0; k < flags.size();) {
    if (!(flags[k] & sf::rest)) {
      ++k;
      continue;
    }
    std::size_t e = k;
    while (e + 1 < flags.size() && (flags[e + 1] & sf::rest)) ++e;
    const double mid = static_cast<double>(k + e) / 2.0 - d;
    for (int i = 0; i < 3; ++i)
      per_axis[i].push_back((interpolate_at(m.pos_mm, mid, i) - interpolate_at(m.cmd_mm, mid, i)) * 1000.0);
    k = e + 1;
  }
  ss = 0.0, n = 0;
  for (const auto& v : per_axis) {
    const double r = rms_about_mean(v);
    ss += r * r * static_cast<double>(v.size()), n += v.size();
  }
  a.rest_rms_um = n > 0 ? std::sqrt(ss / static_cast<double>(n)) : 0.0;
  return a;
}

// ζ of a sensor at f0_hz whose damping term 2ζ/ω0 is `damping_s` below that of ζ.
double zeta_less_damping(double zeta, double f0_hz, double damping_s) {
  const double w0 = 2.0 * std::numbers::pi * f0_hz;
  return std::max(0.0, (2.0 * zeta / w0 - damping_s) * w0 / 2.0);
}

// (I + E)⁻¹ applied to the data-sheet mounting of one sensor: its corrected to_machine.
void apply_sensor(const Eigen::Matrix3d& e, double damping_s, SensorSpec& spec) {
  spec.to_machine = (Eigen::Matrix3d::Identity() + e).inverse() * spec.to_machine;
  spec.zeta = zeta_less_damping(spec.zeta, spec.f0_hz, damping_s);
}

// Strip crossings (runs of lit samples of one strip) and the set-point's speed along the
// strip at each; distinct speeds differ by more than 25 %. Throws when there are no two
// speeds: scale (∝ distance) and 2ζ/ω0 (∝ speed) are then confounded at the strips.
void check_crossings(const Measurement& m, const RunMeta& meta, Identification& id) {
  const auto& fixes = m.raw.schedule.fixes;
  const double fs = m.fs_hz;
  const auto gap = static_cast<std::size_t>(std::max(1.0, 0.05 * fs));
  const double d = meta.acquisition.daq_group_delay_samples;
  std::vector<double> speeds;
  std::vector<std::size_t> last_k(meta.psd.size(), 0), first_k(meta.psd.size(), 0);
  std::vector<bool> open(meta.psd.size(), false);
  auto close = [&](std::size_t s) {
    if (!open[s]) return;
    open[s] = false;
    const double mid = 0.5 * static_cast<double>(first_k[s] + last_k[s]) - d;  // sensor time → set-point time
    const auto k = static_cast<std::size_t>(std::clamp(mid, 1.0, static_cast<double>(m.cmd_mm.size()) - 2.0));
    const int ax = axis_index(meta.psd[s].measures);
    if (ax < 0) return;
    const double v = std::abs(m.cmd_mm[k + 1][ax] - m.cmd_mm[k - 1][ax]) * fs / 2.0;
    if (v > 0.1) speeds.push_back(v), ++id.strip_crossings;
  };
  for (const auto& f : fixes) {
    if (f.strip < 0 || static_cast<std::size_t>(f.strip) >= meta.psd.size()) continue;
    const auto s = static_cast<std::size_t>(f.strip);
    if (open[s] && f.k > last_k[s] + gap) close(s);
    if (!open[s]) open[s] = true, first_k[s] = f.k;
    last_k[s] = f.k;
  }
  for (std::size_t s = 0; s < open.size(); ++s) close(s);
  std::sort(speeds.begin(), speeds.end());
  for (double v : speeds)
    if (id.crossing_speeds_mm_s.empty() || v > 1.25 * id.crossing_speeds_mm_s.back())
      id.crossing_speeds_mm_s.push_back(v);
  if (id.crossing_speeds_mm_s.size() < 2) {
    char b[160];
    std::snprintf(
        b, sizeof b, "%zu strip crossings, %s", id.strip_crossings,
        speeds.empty()
            ? "none while moving"
            : ("all at " + std::to_string(static_cast<int>(std::lround(speeds.front() * 60.0))) + " mm/min").c_str());
    throw InputError(
        std::string("identify: the run crosses its PSD strips at one speed at most (") + b +
        "): a scale error and a 2ζ/ω0 error look alike there; run the identification program (eical gen-nc identify), "
        "which crosses every strip at 2, 4 and 6.5 m/min");
  }
}

// The identification's covariance in the layout of sensor_model_covariance.hpp: per axis i
// the block of its filter's E_ij (the row's terms are fitted together), the damping and
// delay variances; the data sheet's (diagonal) where nothing was fitted. The filter's σ
// does not see what its model leaves out (the bias following the case temperature, the
// sensors' second-order terms; the strips' nonlinearity is a parameter of the filter, its
// share of the scale in the E block's covariance): against the
// simulator's truth on 12 machines drawn within the data sheet the scale terms erred by
// 1.46 σ rms, the cross terms by 0.9 σ (tests/accuracy); with the strips' nonlinearity
// fitted, 1.06 σ over 16 machines at the identification's own temperature. The margin
// stands in for the scale's temperature coefficient between identification and test, not
// yet a source of its own (docs/accuracy.md). The calibration carries σ × kSigmaMargin.
constexpr double kSigmaMargin = 1.5;
dsp::SensorModelCovariance covariance_of(const PassResult& last, const Identification& id, const RunMeta& meta) {
  dsp::SensorModelCovariance c = dsp::datasheet_covariance(meta.sensors, meta.acquisition.fs_hz);
  c.source = id.method;
  for (int i = 0; i < 3; ++i) {
    const AxisFit& af = last.axis[i];
    for (int j = 0; j < 3; ++j) {
      const int pj = af.layout.e[j];
      const int sj = owner(meta, j);
      if (pj < 0 || sj < 0) continue;
      for (int k = 0; k < 3; ++k) {
        const int pk = af.layout.e[k];
        const int sk = owner(meta, k);
        if (pk < 0 || sk < 0) continue;
        c.covariance(dsp::error_index(sj, i, j), dsp::error_index(sk, i, k)) =
            kSigmaMargin * kSigmaMargin * af.cov(pj, pk);
      }
    }
  }
  for (int s = 0; s < 2; ++s)
    if (id.sensor[s].damping_s.fitted)
      c.covariance(dsp::damping_index(s), dsp::damping_index(s)) =
          std::pow(kSigmaMargin * id.sensor[s].damping_s.sigma, 2);
  const auto& dl = id.delay_reference.valid ? id.delay_reference : id.delay_setpoint;
  if (id.delay_identified && dl.valid) {
    const double u = kSigmaMargin * dl.sigma / meta.acquisition.fs_hz;
    c.covariance(dsp::kDelayIndex, dsp::kDelayIndex) = u * u;
  }
  return c;
}

// A damping term the run resolves less well than the data sheet promises (a small circle's
// strips are crossed at low speeds, where 2ζ/ω0·v is a fraction of a µm) is weighed with the
// data sheet instead of replacing it: where the two agree (within twice their combined σ)
// the calibration carries their inverse-variance mean and its σ, never worse than the data
// sheet's; where they do not, the sensor is off its data sheet and the run's value stands.
void weigh_damping_with_datasheet(const RunMeta& datasheet, Identification& id) {
  const dsp::SensorModelCovariance ds = dsp::datasheet_covariance(datasheet.sensors, datasheet.acquisition.fs_hz);
  for (int s = 0; s < 2; ++s) {
    const Estimate& d = id.sensor[s].damping_s;
    const int p = dsp::damping_index(s);
    const double u_run = id.covariance.sigma(p), u_sheet = ds.sigma(p);
    if (!d.fitted || !(u_run > u_sheet) || !(u_sheet > 0.0)) continue;
    const double u_both = std::hypot(u_run, u_sheet);
    const char* who = s == 0 ? "table" : "head";
    char b[320];
    if (std::abs(d.value) > 2.0 * u_both) {
      std::snprintf(b, sizeof b,
                    "%s sensor: 2ζ/ω0 %+.2f ± %.2f µs from the data sheet's, more than twice their combined σ: off its "
                    "data sheet, the run's value kept",
                    who, d.value * 1e6, u_run * 1e6);
      id.notes.emplace_back(b);
      continue;
    }
    const double w = u_sheet * u_sheet / (u_both * u_both);  // the run's weight
    const double value = w * d.value, u = u_run * u_sheet / u_both;
    SensorSpec& spec = id.sensors[s];
    spec.zeta = zeta_less_damping(datasheet.sensors[s].zeta, spec.f0_hz, value);  // value: data sheet − identified
    id.covariance.covariance(p, p) = u * u;
    std::snprintf(b, sizeof b,
                  "%s sensor: 2ζ/ω0 %+.2f ± %.2f µs from the data sheet's, less certain than its ± %.2f µs: weighed "
                  "with it, %+.2f ± %.2f µs (ζ = %.4f)",
                  who, d.value * 1e6, u_run * 1e6, u_sheet * 1e6, value * 1e6, u * 1e6, spec.zeta);
    id.notes.emplace_back(b);
  }
}

// Throws when the run cannot identify: no frames, no reference to identify against, or
// no PSD strips.
void check_identifiable(const Run& run, const IdentifyOptions& o) {
  if (run.frames.empty()) throw InputError("identify: run '" + run.meta.id + "' holds no frames");
  if (o.against_reference && !(run.channels.ref[0] || run.channels.ref[1] || run.channels.ref[2]))
    throw InputError("identify: run '" + run.meta.id + "' has no reference instrument to identify against");
  // Without strips the set-point at standstills alone leaves the damping term unknown and
  // the scale barely better than the data sheet (a step without strips: E_xx ± 170 ppm
  // against the data sheet's ± 260): refused like a run that crosses them at one speed.
  if (!o.against_reference && run.meta.psd.empty())
    throw InputError("identify: run '" + run.meta.id +
                     "' has no PSD strips: the sensors are identified from strip crossings at several speeds "
                     "(run the identification program, eical gen-nc identify, or identify against a reference, "
                     "--compare-reference)");
}

// A pass's estimate applied to sensor s of `meta`: E from the columns it owns, Δ(2ζ/ω0)
// weighted over its axes (where the data said something). Returns the Δ(2ζ/ω0) applied, s.
double apply_pass(const PassResult& pr, int s, RunMeta& meta) {
  Eigen::Matrix3d e = Eigen::Matrix3d::Zero();
  double wsum = 0.0, dsum = 0.0;
  for (int j = 0; j < 3; ++j) {
    if (owner(meta, j) != s || !pr.moved[j]) continue;
    for (int i = 0; i < 3; ++i) e(i, j) = pr.axis[i].theta[pr.axis[i].layout.e[j]];
    const AxisFit& af = pr.axis[j];
    if (af.layout.damping >= 0 && af.sigma[af.layout.damping] < 0.5 * kPriorDampingMs) {
      const double sg = af.sigma[af.layout.damping];
      wsum += 1.0 / (sg * sg), dsum += af.theta[af.layout.damping] / (sg * sg);
    }
  }
  const double damping_s = wsum > 0.0 ? dsum / wsum * 1e-3 : 0.0;
  apply_sensor(e, damping_s, meta.sensors[s]);
  return damping_s;
}

// The passes, each fitting what the one before left: `meta` ends with every pass's estimate
// applied, damping_total_s with each sensor's summed Δ(2ζ/ω0). Returns the last pass.
PassResult iterate_passes(const Run& run, const IdentifyOptions& o, RunMeta& meta, double damping_total_s[2],
                          int& iterations) {
  PassResult last;
  for (int it = 0; it < std::max(1, o.iterations); ++it) {
    last = PassResult{};  // one pass's trace in memory at a time (a 10 kHz trace is 200 B a sample)
    last = fit_pass(run, meta, o);
    for (int s = 0; s < 2; ++s) damping_total_s[s] += apply_pass(last, s, meta);
    iterations = it + 1;
  }
  return last;
}

// What the data sheet and the identified model leave unexplained.
void compare_with_datasheet(const Run& run, const RunMeta& identified, Identification& id) {
  const Agreement before = agreement(run, run.meta), after = agreement(run, identified);
  id.psd_rms_before_um = before.psd_rms_um, id.rest_rms_before_um = before.rest_rms_um;
  id.psd_rms_after_um = after.psd_rms_um, id.rest_rms_after_um = after.rest_rms_um;
}

// Sensor s: its total error against the data sheet (`datasheet`), with the last pass's σ;
// its damping term where identified; its bias at the first standstill.
void report_sensor(int s, const PassResult& last, const RunMeta& datasheet, const RunMeta& meta, double damping_total_s,
                   Identification& id) {
  SensorEstimate& se = id.sensor[s];
  const Eigen::Matrix3d e_total =
      datasheet.sensors[s].to_machine * meta.sensors[s].to_machine.inverse() - Eigen::Matrix3d::Identity();
  double wsum = 0.0;
  for (int j = 0; j < 3; ++j) {
    if (owner(meta, j) != s || !last.moved[j]) continue;
    se.moved = true;
    for (int i = 0; i < 3; ++i) {
      const AxisFit& af = last.axis[i];
      se.error[i][j] = {e_total(i, j), af.sigma[af.layout.e[j]], true};
    }
    const AxisFit& own = last.axis[j];
    // The damping term counts where the data said something (no PSD strip on z: nothing).
    if (own.layout.damping >= 0 && own.sigma[own.layout.damping] < 0.5 * kPriorDampingMs)
      wsum += 1.0 / std::pow(own.sigma[own.layout.damping] * 1e-3, 2);
  }
  if (wsum > 0.0)
    se.damping_s = {damping_total_s, 1.0 / std::sqrt(wsum), true};
  else if (se.moved)
    id.notes.push_back(std::string(s == 0 ? "table" : "head") +
                       " sensor: 2ζ/ω0 not identified (no PSD strip along its axes): data sheet kept");
  // Bias at the first standstill (sensor axes, gravity removed): what the rest window took out.
  const double g = meta.site.g_mps2;
  const Eigen::Vector3d gravity(0.0, 0.0, g);
  const Eigen::Vector3d b_machine = last.m.raw.rest_bias_mps2[s] - gravity;
  se.rest_bias_g = datasheet.sensors[s].bias_g + meta.sensors[s].to_machine.inverse() * b_machine / g;
}

// The machine's parameters fitted alongside: rest offsets, backlash, the strips' mounting offsets.
void report_machine(const PassResult& last, const RunMeta& meta, Identification& id) {
  for (int i = 0; i < 3; ++i) {
    const AxisFit& af = last.axis[i];
    if (af.layout.x0 >= 0) id.rest_offset_um[i] = {af.theta[af.layout.x0], af.sigma[af.layout.x0], true};
    if (af.layout.backlash >= 0) id.backlash_um[i] = {af.theta[af.layout.backlash], af.sigma[af.layout.backlash], true};
  }
  id.psd_offset_um.resize(meta.psd.size());
  id.psd_nonlinearity.resize(meta.psd.size());
  for (std::size_t s = 0; s < meta.psd.size(); ++s) {
    const int i = axis_index(meta.psd[s].measures);
    if (i < 0) continue;
    const AxisFit& af = last.axis[i];
    if (s < af.layout.strip.size() && af.layout.strip[s] >= 0)
      id.psd_offset_um[s] = {af.theta[af.layout.strip[s]], af.sigma[af.layout.strip[s]], true};
    if (s < af.layout.strip_nl.size() && af.layout.strip_nl[s] >= 0)
      id.psd_nonlinearity[s] = {af.theta[af.layout.strip_nl[s]], af.sigma[af.layout.strip_nl[s]], true};
  }
}

// The DAQ delay: PSD readings behind the set-point (with servo lag) and the reference; the
// data sheet's is kept unless the reference gives it or the caller accepts the set-point's.
void identify_delay(const Measurement& m, const Run& run, const RunMeta& meta, const IdentifyOptions& o,
                    Identification& id) {
  id.delay_setpoint = estimate_delay(m, meta, DelayReference::setpoint);
  if (run.channels.ref[0] || run.channels.ref[1])
    id.delay_reference = estimate_delay(m, meta, DelayReference::reference);
  id.daq_group_delay_samples = run.meta.acquisition.daq_group_delay_samples;
  if (id.delay_reference.valid) {
    id.daq_group_delay_samples = id.delay_reference.samples, id.delay_identified = true;
  } else if (o.delay_from_setpoint && id.delay_setpoint.valid) {
    id.daq_group_delay_samples = id.delay_setpoint.samples, id.delay_identified = true;
    id.notes.push_back(
        "DAQ delay taken from the PSD readings against the set-point: it includes the axes' mean servo lag");
  } else if (id.delay_setpoint.valid) {
    id.notes.push_back(
        "DAQ delay kept at the data sheet's: against the set-point the PSD readings lag by the delay plus the servo "
        "lag (no reference in the run)");
  }
}

}  // namespace

std::vector<std::string> less_certain_than_datasheet(const Identification& id,
                                                     const dsp::SensorModelCovariance& datasheet) {
  // What the calibration would carry (its covariance, margins included) against the data sheet.
  std::vector<std::string> out;
  char b[200];
  for (int s = 0; s < 2; ++s) {
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        const Estimate& e = id.sensor[s].error[i][j];
        const int p = dsp::error_index(s, i, j);
        const double u = id.covariance.sigma(p), lim = datasheet.sigma(p);
        if (e.fitted && !(u <= lim)) {
          std::snprintf(b, sizeof b, "%s (%+.0f ± %.0f ppm, the data sheet ± %.0f ppm)", dsp::parameter_name(p).c_str(),
                        e.value * 1e6, u * 1e6, lim * 1e6);
          out.emplace_back(b);
        }
      }
    const int p = dsp::damping_index(s);
    const double u = id.covariance.sigma(p), lim = datasheet.sigma(p);
    if (id.sensor[s].damping_s.fitted && !(u <= lim)) {
      std::snprintf(b, sizeof b, "%s (± %.2f µs, the data sheet ± %.2f µs)", dsp::parameter_name(p).c_str(), u * 1e6,
                    lim * 1e6);
      out.emplace_back(b);
    }
  }
  return out;
}

Identification identify_sensors(const Run& run, const IdentifyOptions& options) {
  check_identifiable(run, options);
  Identification id;
  id.method = options.against_reference ? "ref" : "psd";
  RunMeta meta = run.meta;
  double damping_total_s[2] = {0.0, 0.0};
  PassResult last = iterate_passes(run, options, meta, damping_total_s, id.iterations);
  id.psd_observations = last.psd_obs, id.rest_observations = last.rest_obs, id.standstills = last.standstills;
  if (!options.against_reference) check_crossings(last.m, meta, id);
  for (int s = 0; s < 2; ++s) report_sensor(s, last, run.meta, meta, damping_total_s[s], id);
  report_machine(last, run.meta, id);
  identify_delay(last.m, run, meta, options, id);
  for (int s = 0; s < 2; ++s) id.sensors[s] = meta.sensors[s];
  if (!id.sensor[0].moved && !id.sensor[1].moved) throw InputError("identify: no axis moved more than 0.5 mm");
  for (int i = 0; i < 3; ++i) id.position_nis[i] = last.axis[i].position_nis;
  id.covariance = covariance_of(last, id, run.meta);
  weigh_damping_with_datasheet(run.meta, id);
  for (int s = 0; s < 2; ++s) meta.sensors[s].zeta = id.sensors[s].zeta;  // the comparison's model too
  last.m = Measurement{};  // the comparison integrates the run twice more: one trace at a time
  if (options.compare_with_datasheet) compare_with_datasheet(run, meta, id);
  return id;
}

void apply_identification(const Identification& id, RunMeta& meta, PipelineConfig* config) {
  for (int s = 0; s < 2; ++s) meta.sensors[s] = id.sensors[s];
  meta.acquisition.daq_group_delay_samples = id.daq_group_delay_samples;
  if (config) {
    for (int s = 0; s < 2; ++s) config->sensors[s] = id.sensors[s], config->calibration[s] = id.calibration[s];
    config->acquisition.daq_group_delay_samples = id.daq_group_delay_samples;
  }
}

}  // namespace eical::dsp::identify
