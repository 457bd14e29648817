#include "dsp/uncertainty/error_field.hpp"

#include "dsp/core/error.hpp"
#include "dsp/fusion/rts_smoother.hpp"
#include "dsp/supports/psd_nonlinearity.hpp"

#include <Eigen/Cholesky>

#include <algorithm>
#include <cmath>
#include <set>

namespace eical::dsp::uncertainty {
namespace {

// x = G z draws N(0, C): LDLᵀ with pivoting takes a semi-definite C. The parameters differ
// in units by orders of magnitude (E ~ 1e-4, α_b ~ 100 µg/°C): factored in correlation form
// so that the jitter that keeps it definite is relative to each parameter's own variance.
Eigen::MatrixXd draw_factor(const Eigen::MatrixXd& c) {
  const Eigen::Index m = c.rows();
  if (m == 0) return {};
  Eigen::VectorXd s = c.diagonal().cwiseMax(0.0).cwiseSqrt();
  for (Eigen::Index i = 0; i < m; ++i)
    if (!(s[i] > 0.0)) s[i] = 1.0;  // a parameter without variance: its row and column are zero
  const Eigen::MatrixXd r = s.cwiseInverse().asDiagonal() * c * s.cwiseInverse().asDiagonal();
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(r + 1e-12 * Eigen::MatrixXd::Identity(m, m));
  const Eigen::VectorXd d = ldlt.vectorD().cwiseMax(0.0).cwiseSqrt();
  Eigen::MatrixXd l = ldlt.matrixL();
  l = l * d.asDiagonal();
  Eigen::MatrixXd g = ldlt.transpositionsP().transpose() * l;
  for (Eigen::Index i = 0; i < m; ++i)
    if (!(c(i, i) > 0.0)) g.row(i).setZero();
  return s.asDiagonal() * g;
}

// Linear interpolation of a trace at a fractional position (clamped).
template <typename V>
V at(const std::vector<V>& x, double pos) {
  if (pos <= 0.0) return x.front();
  const auto i = static_cast<std::size_t>(pos);
  if (i + 1 >= x.size()) return x.back();
  const double f = pos - static_cast<double>(i);
  return (1.0 - f) * x[i] + f * x[i + 1];
}

// The truth the noise draws simulate: the white noise measured at rest (the data sheet's
// where the run has no quiet stretch to measure it in) and the data sheet's bias walk,
// whatever the fusion's model assumes (a model that assumes less is judged by what it
// then misses, one that assumes more by what its caution costs). 1 µg = g µm/s².
fusion::ErrorModel simulated_truth(const fusion::ErrorModel& coarse_model, const ErrorFieldInput& in) {
  fusion::ErrorModel truth = coarse_model;
  truth.bias_walk_um_s2_rts = std::hypot(in.bias_walk_ug_per_rts[0], in.bias_walk_ug_per_rts[1]) * in.g_mps2;
  const double rel_ug = std::isfinite(in.rel_noise_ug_per_rthz)
                            ? in.rel_noise_ug_per_rthz
                            : std::hypot(in.sensor_noise_ug_per_rthz[0], in.sensor_noise_ug_per_rthz[1]);
  truth.accel_noise_um_s2_rthz = rel_ug * in.g_mps2;
  return truth;
}

void check_path(const CoarsePath& path, std::size_t nc) {
  const bool have_temp = !path.temp_c.empty();
  if (path.pos_mm.size() != nc || path.vel_mm_s.size() != nc || path.acc_mm_s2.size() != nc ||
      (have_temp && path.temp_c.size() != nc))
    throw InputError("uncertainty: the coarse path does not match its schedule");
}

// One smoother pass over pseudo-data: what is left of a unit error after the supports.
struct Responder {
  const CoarseSchedule& coarse;
  const ErrorFieldInput& in;

  // dx, dv: the error's position and velocity per coarse sample; strip: the one strip that
  // reads 1 µm (−1: none), or what `fix_error_um` says each fix of it reads; unit: the
  // parameter's value that made them.
  std::vector<Eigen::Vector3d> operator()(const std::vector<Eigen::Vector3d>& dx_mm,
                                          const std::vector<Eigen::Vector3d>& dv_mm_s, int strip, double unit,
                                          double (*fix_error_um)(const fusion::PositionFix&, const PsdSpec&) = nullptr,
                                          const PsdSpec* spec = nullptr) const {
    const std::size_t nc = coarse.sample_index.size();
    fusion::SupportSchedule sched = coarse.schedule;
    for (auto& f : sched.fixes)
      f.position_um = f.strip != strip ? 0.0 : fix_error_um && spec ? fix_error_um(f, *spec) : 1.0;
    for (auto& m : sched.velocity_means) {
      const Eigen::Vector3d vm = dv_mm_s[m.k] * 1000.0;
      for (int i = 0; i < 3; ++i) m.mean_um_s[i] = vm[i];
    }
    fusion::SmootherInput si;
    si.sample_index = &coarse.sample_index;
    si.vel_mm_s = &dv_mm_s;
    si.pos_mm = &dx_mm;
    si.schedule = &sched;
    si.fs_hz = in.fs_hz;
    si.model = coarse.model;
    si.start_bias_sigma_um_s2 = in.start_bias_sigma_um_s2;
    const fusion::SmootherOutput out = fusion::smooth(si);
    std::vector<Eigen::Vector3d> r(nc);
    for (std::size_t j = 0; j < nc; ++j) r[j] = (dx_mm[j] * 1000.0 - out.dx_um[j]) / unit;
    return r;
  }
};

constexpr double kUnitE = 1e-4, kUnitTau = 1e-3;

// Whether the path moves along axis j (more than 1 µm).
bool column_moves(const std::vector<Eigen::Vector3d>& p, int j) {
  double lo = 1e300, hi = -1e300;
  for (const auto& x : p) lo = std::min(lo, x[j]), hi = std::max(hi, x[j]);
  return hi - lo > 1e-3;
}

// An error that follows the motion (E·v, τ·a) has no velocity where the machine rests, and
// that is what a standstill reads. A coarse block counts as a standstill when any of its
// samples rests, while the path is read at its last sample, which may already move: there
// the standstill must read zero, not the motion's share (the smoother would take it for a
// velocity error and carry it into the rest of the travel).
void standstills_read_no_motion(const CoarseSchedule& coarse, std::vector<Eigen::Vector3d>& dv_mm_s) {
  const auto& flags = coarse.schedule.flags;
  for (std::size_t k = 0; k < dv_mm_s.size() && k < flags.size(); ++k)
    if (flags[k] & fusion::schedule_flag::rest) dv_mm_s[k].setZero();
}

// Column j of E: every axis' error from the motion along j, per unit E.
std::vector<Eigen::Vector3d> scale_response(const Responder& respond, const CoarsePath& path, int j) {
  const std::size_t nc = path.pos_mm.size();
  std::vector<Eigen::Vector3d> dx(nc), dv(nc);
  for (std::size_t k = 0; k < nc; ++k)
    dx[k] = Eigen::Vector3d::Constant(path.pos_mm[k][j] * kUnitE),
    dv[k] = Eigen::Vector3d::Constant(path.vel_mm_s[k][j] * kUnitE);
  standstills_read_no_motion(respond.coarse, dv);
  return respond(dx, dv, -1, kUnitE);
}

// The timing term (v·τ), per unit τ.
std::vector<Eigen::Vector3d> timing_response(const Responder& respond, const CoarsePath& path) {
  const std::size_t nc = path.pos_mm.size();
  std::vector<Eigen::Vector3d> dx(nc), dv(nc);
  for (std::size_t k = 0; k < nc; ++k) dx[k] = path.vel_mm_s[k] * kUnitTau, dv[k] = path.acc_mm_s2[k] * kUnitTau;
  standstills_read_no_motion(respond.coarse, dv);
  return respond(dx, dv, -1, kUnitTau);
}

// Sensor s' α_b of 1 µg/°C: a bias (T − T_rest)·1 µg, integrated twice (trapezoid on the coarse grid).
std::vector<Eigen::Vector3d> temperature_response(const Responder& respond, const CoarsePath& path, int s) {
  const std::size_t nc = path.pos_mm.size();
  const auto& idx = respond.coarse.sample_index;
  const double unit_mps2 = 1e-6 * respond.in.g_mps2;
  std::vector<Eigen::Vector3d> dx(nc, Eigen::Vector3d::Zero()), dv(nc, Eigen::Vector3d::Zero());
  for (std::size_t k = 1; k < nc; ++k) {
    const double dt = static_cast<double>(idx[k] - idx[k - 1]) / respond.in.fs_hz;
    const double a0 = path.temp_c[k - 1][s] * unit_mps2 * 1000.0, a1 = path.temp_c[k][s] * unit_mps2 * 1000.0;  // mm/s²
    dv[k] = dv[k - 1] + Eigen::Vector3d::Constant(0.5 * (a0 + a1) * dt);
    dx[k] = dx[k - 1] + 0.5 * (dv[k - 1] + dv[k]) * dt;
  }
  return respond(dx, dv, -1, 1.0);
}

// What a strip's nonlinearity of 1 makes a fix read too far, µm.
double nonlinearity_error_um(const fusion::PositionFix& f, const PsdSpec& spec) {
  return supports::psd_nonlinearity_shape_um(spec, f.position_um);
}

// Per strip of the run with fixes: its nonlinearity's response, per unit nl.
std::vector<std::vector<Eigen::Vector3d>> strip_nonlinearity_responses(const Responder& respond,
                                                                       const std::vector<PsdSpec>& psd) {
  const std::size_t nc = respond.coarse.sample_index.size();
  const std::vector<Eigen::Vector3d> zero(nc, Eigen::Vector3d::Zero());
  std::set<int> strips;
  for (const auto& f : respond.coarse.schedule.fixes) strips.insert(f.strip);
  std::vector<std::vector<Eigen::Vector3d>> response;
  for (int s : strips) {
    if (s < 0 || static_cast<std::size_t>(s) >= psd.size()) continue;
    if (response.size() <= static_cast<std::size_t>(s)) response.resize(static_cast<std::size_t>(s) + 1);
    response[static_cast<std::size_t>(s)] =
        respond(zero, zero, s, 1.0, &nonlinearity_error_um, &psd[static_cast<std::size_t>(s)]);
  }
  return response;
}

// Per PSD strip of the fixes: the strip reads 1 µm too far, the (error-free) trace is
// pulled towards it.
std::vector<std::vector<Eigen::Vector3d>> strip_responses(const Responder& respond) {
  const std::size_t nc = respond.coarse.sample_index.size();
  const std::vector<Eigen::Vector3d> zero(nc, Eigen::Vector3d::Zero());
  std::set<int> strips;
  for (const auto& f : respond.coarse.schedule.fixes) strips.insert(f.strip);
  std::vector<std::vector<Eigen::Vector3d>> response;
  for (int s : strips) {
    if (s < 0) continue;
    if (response.size() <= static_cast<std::size_t>(s)) response.resize(static_cast<std::size_t>(s) + 1);
    response[static_cast<std::size_t>(s)] = respond(zero, zero, s, 1.0);
  }
  return response;
}

// Whether the schedule flags the first move's start itself (the standstill detector still
// sees the rest for the DAQ's delay after the set-point moved): then that step is drawn
// there, not also in the start's bias (it was counted twice).
bool first_move_flagged(const std::vector<std::uint8_t>& flags) {
  namespace sf = fusion::schedule_flag;
  for (const std::uint8_t f : flags) {
    if (f & sf::move_start) return true;
    if (!(f & sf::rest)) return false;
  }
  return false;
}

// One realisation of the integration's error after a smoother (per coarse sample, µm): the
// error simulated with the `truth` model, the supports' observations of it with their own
// errors, the smoother with `fused` (the pipeline's model, or the truth itself for the
// bound) subtracting its estimate. `own_fix_sigma`: the smoother weighs each strip fix by
// the strip's own noise only (the bound; the pipeline adds the sensor model's share).
std::vector<Eigen::Vector3d> integration_error_draw(const CoarseSchedule& coarse, const ErrorFieldInput& input,
                                                    const fusion::ErrorModel& truth, const fusion::ErrorModel& fused,
                                                    bool own_fix_sigma, std::mt19937_64& rng) {
  const double fs_hz = input.fs_hz;
  const Eigen::Vector3d& start_bias_sigma = input.start_bias_sigma_um_s2;
  namespace sf = fusion::schedule_flag;
  std::normal_distribution<double> g;
  const std::size_t nc = coarse.sample_index.size();
  const auto& flags = coarse.schedule.flags;
  const double start_step_um_s2 = first_move_flagged(flags) ? 0.0 : truth.bias_step_um_s2;
  std::vector<Eigen::Vector3d> ex(nc), ev(nc), eb(nc);
  const fusion::StateCov p0 = fusion::initial_covariance(truth, 0, 0.0);  // its velocity term
  for (int a = 0; a < 3; ++a) {
    // Drawn one by one, the bias first (see below: a call's arguments have no order).
    const double z_bias = g(rng), z_vel = g(rng);
    fusion::Vec3 e(0.0, std::sqrt(p0(1, 1)) * z_vel, std::hypot(start_bias_sigma[a], start_step_um_s2) * z_bias);
    fusion::Discrete d;
    std::int64_t last_gap = 0;
    Eigen::LLT<fusion::Mat3> llt;
    for (std::size_t k = 0; k < nc; ++k) {
      if (k > 0) {
        const std::int64_t gap = coarse.sample_index[k] - coarse.sample_index[k - 1];
        if (gap != last_gap) {
          d = fusion::discretise(truth, static_cast<double>(gap) / fs_hz);
          llt.compute(d.Q.topLeftCorner<3, 3>() + 1e-18 * fusion::Mat3::Identity());
          last_gap = gap;
        }
        // Drawn one by one (last component first, the order these runs were made with): the
        // arguments of a call have no order, and another compiler would draw another field.
        const double w2 = g(rng), w1 = g(rng), w0 = g(rng);
        e = d.F.topLeftCorner<3, 3>() * e + llt.matrixL() * fusion::Vec3(w0, w1, w2);
      }
      if ((flags[k] & sf::move_start) && truth.bias_step_um_s2 > 0.0) e[2] += truth.bias_step_um_s2 * g(rng);
      ex[k][a] = e[0], ev[k][a] = e[1], eb[k][a] = e[2];
    }
  }
  // What the pipeline integrated (the error: the motion itself is known) and saw at the supports.
  std::vector<Eigen::Vector3d> pos(nc), vel(nc);
  for (std::size_t k = 0; k < nc; ++k) {
    pos[k] = ex[k] / 1000.0;
    Eigen::Vector3d v = ev[k];
    // A standstill's true velocity is not exactly zero, a held axis' not either.
    const double s = flags[k] & sf::rest ? std::max(0.0, static_cast<double>(coarse.schedule.zupt_sigma_um_s[k]))
                                         : coarse.model.nbs_sigma_um_s;
    for (int a = 0; a < 3; ++a) v[a] += s * g(rng);
    vel[k] = v / 1000.0;
  }
  fusion::SupportSchedule sched = coarse.schedule;
  for (std::size_t i = 0; i < sched.fixes.size(); ++i) {
    sched.fixes[i].position_um = coarse.fix_noise_um[i] * g(rng);
    if (own_fix_sigma)
      sched.fixes[i].sigma_um = std::max(coarse.fix_noise_um[i], 1e-6), sched.fixes[i].model_sigma_um = 0.0;
  }
  for (auto& m : sched.velocity_means)
    for (int a = 0; a < 3; ++a) m.mean_um_s[a] = ev[m.k][a] - m.lag_s * eb[m.k][a] + m.sigma_um_s * g(rng);
  fusion::SmootherInput si;
  si.sample_index = &coarse.sample_index;
  si.vel_mm_s = &vel;
  si.pos_mm = &pos;
  si.schedule = &sched;
  si.fs_hz = fs_hz;
  si.model = fused;
  si.start_bias_sigma_um_s2 = start_bias_sigma;
  const fusion::SmootherOutput out = fusion::smooth(si);
  std::vector<Eigen::Vector3d> r(nc);
  for (std::size_t k = 0; k < nc; ++k) r[k] = ex[k] - out.dx_um[k];
  return r;
}

std::vector<Eigen::Vector3d> noise_draw(const CoarseSchedule& coarse, const ErrorFieldInput& input,
                                        std::mt19937_64& rng) {
  return integration_error_draw(coarse, input, simulated_truth(coarse.model, input), coarse.model, false, rng);
}

}  // namespace

double ErrorField::coarse_position(double at) const {
  const double c = (at + delay_ + 1.0) / static_cast<double>(coarse_.block) - 1.0;
  return std::clamp(c, 0.0, static_cast<double>(coarse_.sample_index.size()) - 1.0);
}

std::size_t ErrorField::block_for(std::size_t samples, std::size_t max_coarse) noexcept {
  return std::max<std::size_t>(1, (samples + max_coarse - 1) / std::max<std::size_t>(1, max_coarse));
}

ErrorField::ErrorField(const ErrorFieldInput& input) {
  if (!input.schedule || !input.sample_index || !input.pos_mm || !input.vel_mm_s)
    throw InputError("uncertainty: input arrays missing");
  const std::size_t n = std::min(
      {input.schedule->flags.size(), input.sample_index->size(), input.pos_mm->size(), input.vel_mm_s->size()});
  if (n < 2) throw InputError("uncertainty: the measurement holds fewer than 2 samples");
  coarse_ = coarsen(*input.schedule, *input.sample_index, input.model, block_for(n, input.max_coarse), input.fs_hz);
  const bool have_temp = input.temp_c && input.temp_c->size() >= n;
  build(input, coarse_path(coarse_, input.delay_samples, input.fs_hz, *input.pos_mm, *input.vel_mm_s,
                           have_temp ? input.temp_c : nullptr));
}

ErrorField::ErrorField(const ErrorFieldInput& input, CoarseSchedule coarse, const CoarsePath& path)
    : coarse_(std::move(coarse)) {
  if (coarse_.sample_index.size() < 2) throw InputError("uncertainty: the measurement holds fewer than 2 samples");
  build(input, path);
}

void ErrorField::build(const ErrorFieldInput& input, const CoarsePath& path) {
  input_ = input;
  input_.schedule = nullptr, input_.sample_index = nullptr, input_.pos_mm = nullptr, input_.vel_mm_s = nullptr;
  input_.temp_c = nullptr;
  delay_ = input.delay_samples;
  owner_ = input.owner;
  strip_sigma_um_ = input.model_covariance.psd_offset_sigma_um;
  check_path(path, coarse_.sample_index.size());
  const Responder respond{coarse_, input};
  for (std::size_t j = 0; j < 3; ++j) {
    column_moves_[j] = column_moves(path.pos_mm, static_cast<int>(j)) && owner_[j] >= 0;
    if (column_moves_[j]) response_e_[j] = scale_response(respond, path, static_cast<int>(j));
  }
  response_timing_ = timing_response(respond, path);
  if (!path.temp_c.empty())
    for (int s = 0; s < 2; ++s) response_tc_[static_cast<std::size_t>(s)] = temperature_response(respond, path, s);
  if (coarse_.schedule.cupt) {
    response_strip_ = strip_responses(respond);
    if (input.psd_nonlinearity > 0.0) response_strip_nl_ = strip_nonlinearity_responses(respond, input.psd);
  }
  model_factor_ = draw_factor(input.model_covariance.covariance);
}

std::vector<Eigen::Vector3d> draw_noise_bound(const ErrorFieldInput& input, const CoarseSchedule& coarse,
                                              std::mt19937_64& rng) {
  fusion::ErrorModel truth = simulated_truth(coarse.model, input);
  truth.bias_walk_um_s2_rts = 0.0, truth.bias_step_um_s2 = 0.0;
  // A perfect sensor model: no scale or timing left to estimate (as fusion::ErrorCovariance).
  truth.scale_state_ppm = {}, truth.timing_state_us = {};
  return integration_error_draw(coarse, input, truth, truth, true, rng);
}

void ErrorField::draw_bound(std::mt19937_64& rng, const std::vector<double>& at_pos,
                            std::vector<Eigen::Vector3d>& error_um) const {
  const std::vector<Eigen::Vector3d> e = draw_noise_bound(input_, coarse_, rng);
  error_um.resize(at_pos.size());
  for (std::size_t k = 0; k < at_pos.size(); ++k) error_um[k] = at(e, coarse_position(at_pos[k]));
}

NoiseDraw draw_noise(const ErrorFieldInput& input, const CoarseSchedule& coarse, std::mt19937_64 rng) {
  NoiseDraw d;
  d.error_um = noise_draw(coarse, input, rng);
  d.rng = rng;
  return d;
}

void ErrorField::draw(std::mt19937_64& rng, const std::vector<double>& at_pos,
                      std::vector<Eigen::Vector3d>& error_um) const {
  NoiseDraw noise{noise_draw(coarse_, input_, rng), {}};
  noise.rng = rng;
  draw(std::move(noise), at_pos, error_um);
}

void ErrorField::draw(NoiseDraw drawn, const std::vector<double>& at_pos,
                      std::vector<Eigen::Vector3d>& error_um) const {
  error_um.resize(at_pos.size());
  for (std::size_t e = 0; e < at_pos.size(); ++e) error_um[e] = at(drawn.error_um, coarse_position(at_pos[e]));
  add_model(drawn.rng, at_pos, SourceMask{}, error_um);
}

void ErrorField::draw(std::mt19937_64& rng, const std::vector<double>& at_pos, std::vector<Eigen::Vector3d>& error_um,
                      SourceMask mask) const {
  error_um.assign(at_pos.size(), Eigen::Vector3d::Zero());
  if (mask.has(ErrorSource::integration)) {
    const std::vector<Eigen::Vector3d> noise = noise_draw(coarse_, input_, rng);
    for (std::size_t e = 0; e < at_pos.size(); ++e) error_um[e] = at(noise, coarse_position(at_pos[e]));
  }
  add_model(rng, at_pos, mask, error_um);
}

// The sensor model's and the strips' share of a draw, added to `error_um` (the parameters
// are drawn whatever the mask, so a source's draws are the same with or without the others).
void ErrorField::add_model(std::mt19937_64& rng, const std::vector<double>& at_pos, SourceMask mask,
                           std::vector<Eigen::Vector3d>& error_um) const {
  std::normal_distribution<double> g;
  Eigen::VectorXd z(kModelParameters);
  for (int i = 0; i < kModelParameters; ++i) z[i] = g(rng);
  const Eigen::VectorXd theta = model_factor_ * z;
  std::vector<double> offsets(response_strip_.size());
  for (auto& o : offsets) o = strip_sigma_um_ * g(rng);
  std::uniform_real_distribution<double> nl_of(-input_.psd_nonlinearity, input_.psd_nonlinearity);
  std::vector<double> nl(response_strip_nl_.size());
  for (auto& x : nl) x = nl_of(rng);
  const bool scale = mask.has(ErrorSource::sensor_scale), timing = mask.has(ErrorSource::sensor_timing),
             temperature = mask.has(ErrorSource::temperature), strip = mask.has(ErrorSource::strip_offset),
             strip_nl = mask.has(ErrorSource::strip_nonlinearity);
  for (std::size_t e = 0; e < at_pos.size(); ++e) {
    const double c = coarse_position(at_pos[e]);
    Eigen::Vector3d err = Eigen::Vector3d::Zero();
    for (int j = 0; j < 3 && scale; ++j) {
      const auto ju = static_cast<std::size_t>(j);
      if (!column_moves_[ju]) continue;
      const Eigen::Vector3d r = at(response_e_[ju], c);
      for (int i = 0; i < 3; ++i) err[i] += theta[error_index(owner_[ju], i, j)] * r[i];
    }
    if (timing) {
      const Eigen::Vector3d rt = at(response_timing_, c);
      for (int i = 0; i < 3; ++i) {
        const int s = owner_[static_cast<std::size_t>(i)];
        err[i] += ((s >= 0 ? theta[damping_index(s)] : 0.0) + theta[kDelayIndex]) * rt[i];
      }
    }
    for (int s = 0; s < 2 && temperature; ++s) {
      if (response_tc_[static_cast<std::size_t>(s)].empty()) continue;
      const Eigen::Vector3d r = at(response_tc_[static_cast<std::size_t>(s)], c);
      for (int i = 0; i < 3; ++i) err[i] += theta[tc_bias_index(s, i)] * r[i];
    }
    for (std::size_t s = 0; s < response_strip_.size() && strip; ++s)
      if (!response_strip_[s].empty()) err += offsets[s] * at(response_strip_[s], c);
    for (std::size_t s = 0; s < response_strip_nl_.size() && strip_nl; ++s)
      if (!response_strip_nl_[s].empty()) err += nl[s] * at(response_strip_nl_[s], c);
    error_um[e] += err;
  }
}

}  // namespace eical::dsp::uncertainty
