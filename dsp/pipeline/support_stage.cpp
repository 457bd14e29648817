#include "dsp/pipeline/support_stage.hpp"

#include <algorithm>
#include <cmath>

namespace eical::dsp {
namespace {

constexpr std::size_t kMaxRestWindows = 4096;

}  // namespace

SupportStage::SupportStage(const SupportConfig& c, const Acquisition& acq, const std::vector<PsdSpec>& psd, double noise_var_m2ps4,
                           std::size_t capacity)
    : cfg_(c), fs_hz_(acq.fs_hz), step_(fusion::discretise(c.model, 1.0 / acq.fs_hz)),
      detector_(c.standstill, acq.fs_hz, acq.daq_group_delay_samples, noise_var_m2ps4), capacity_(capacity) {
  for (const auto& s : psd) {
    if (psd_.size() >= static_cast<std::size_t>(kMaxPsd)) break;
    psd_.emplace_back(s, acq);
  }
  schedule_.flags.reserve(capacity);
  schedule_.zupt_sigma_um_s.reserve(capacity);
  schedule_.zupt = c.zupt;
  schedule_.cupt = c.cupt;
  schedule_.fixes.reserve(capacity);
  schedule_.velocity_means.reserve(capacity / 100 + 16);
  rests_.reserve(kMaxRestWindows);
  block_len_ = static_cast<std::size_t>(std::max(1.0, std::round(0.02 * acq.fs_hz)));
  block_means_.reserve(kMaxRestWindows);
  reset();
}

void SupportStage::reset() noexcept {
  for (auto& d : psd_) d.reset();
  psd_now_ = {};
  detector_.reset();
  schedule_.flags.clear();
  schedule_.zupt_sigma_um_s.clear();
  schedule_.velocity_means.clear();
  schedule_.fixes.clear();
  rest_sum_.setZero(), rest_sq_.setZero();
  rest_n_ = 0;
  block_means_.clear();
  block_sum_.setZero();
  block_n_ = 0;
  start_bias_sigma_.setZero();
  at_rest_ = started_ = false;
  cmd_at_rest_.setZero();
  open_ = RestWindow{};
  rests_.clear();
  rests_dropped_ = fixes_dropped_ = 0;
  ringing_count_ = 0;
  live_.start(cfg_.model, Eigen::Vector3d::Constant(cfg_.model.bias_step_um_s2));
}

void SupportStage::psd_frame(const Frame& f) noexcept {
  for (std::size_t k = 0; k < psd_.size(); ++k)
    psd_now_[k] = psd_[k].step(f.psd_counts[2 * k], f.psd_counts[2 * k + 1], (f.flags & frame_flag::psd_missing) != 0);
}

void SupportStage::rest_sample(const Eigen::Vector3d& a) noexcept {
  if (!a.allFinite()) return;
  rest_sum_ += a;
  rest_sq_ += a.cwiseProduct(a);
  ++rest_n_;
  block_sum_ += a;
  if (++block_n_ == block_len_) {
    if (block_means_.size() < block_means_.capacity()) block_means_.push_back(block_sum_ / static_cast<double>(block_len_));
    block_sum_.setZero();
    block_n_ = 0;
  }
}

void SupportStage::start() noexcept {
  // The rest window's own scatter: the detector's noise level and how well it fixed the bias.
  if (rest_n_ >= 100) {
    const double n = static_cast<double>(rest_n_);
    const Eigen::Vector3d var = (rest_sq_ / n - (rest_sum_ / n).cwiseAbs2()).cwiseMax(0.0);
    detector_.set_noise(var.mean());
    start_bias_sigma_ = (var / n).cwiseSqrt() * 1e6;  // m/s² → µm/s², white samples
    const std::size_t nb = block_means_.size();
    if (nb >= 3) {  // batch means: σ of the mean = spread of the block means / √blocks
      Eigen::Vector3d mb = Eigen::Vector3d::Zero(), vb = Eigen::Vector3d::Zero();
      for (const auto& b : block_means_) mb += b;
      mb /= static_cast<double>(nb);
      for (const auto& b : block_means_) vb += (b - mb).cwiseAbs2();
      vb /= static_cast<double>(nb - 1);
      start_bias_sigma_ = start_bias_sigma_.cwiseMax((vb / static_cast<double>(nb)).cwiseSqrt() * 1e6);
    }
  } else {
    start_bias_sigma_ = Eigen::Vector3d::Constant(std::sqrt(detector_.noise_var() / std::max<double>(1.0, static_cast<double>(rest_n_))) * 1e6);
  }
  live_.start(cfg_.model, start_bias_sigma_);
  started_ = true;
  at_rest_ = false;
  start_pos_mm_ = Eigen::Vector3d::Constant(NAN);
}

Eigen::Vector3d SupportStage::live_dx_mm() const noexcept {
  return Eigen::Vector3d(live_.axis[0].e[0], live_.axis[1].e[0], live_.axis[2].e[0]) / 1000.0;
}

Eigen::Vector3d SupportStage::live_dv_mm_s() const noexcept {
  return Eigen::Vector3d(live_.axis[0].e[1], live_.axis[1].e[1], live_.axis[2].e[1]) / 1000.0;
}

void SupportStage::close_rest_window() noexcept {
  if (open_.samples == 0) return;
  open_.table_mps2 /= static_cast<double>(open_.samples);
  open_.head_mps2 /= static_cast<double>(open_.samples);
  if (rests_.size() < kMaxRestWindows) rests_.push_back(open_);
  else ++rests_dropped_;
  open_ = RestWindow{};
}

void SupportStage::step(const SupportSample& s) noexcept {
  if (s.k == 0) start_pos_mm_ = s.pos_mm;  // where the integration is anchored
  // The velocity as the live filter corrects it before this sample's update (the lock-in's lag).
  const Eigen::Vector3d vel_corr_mm_s = s.vel_mm_s - live_dv_mm_s();
  RestDecision r = find_rest(s);
  zupt_or_window_mean(s, r);
  const std::uint8_t flags = schedule_flags(s, r);
  predict_and_support_velocity(s, r, flags);
  position_fixes(s, vel_corr_mm_s);
  record(flags, r);
  track_rest_window(s, r);
}

SupportStage::RestDecision SupportStage::find_rest(const SupportSample& s) noexcept {
  double pvv = 0.0;
  for (const auto& f : live_.axis) pvv = std::max(pvv, f.P(1, 1));
  RestDecision r;
  r.det = detector_.step(s.accel_valid ? Eigen::Vector3d(s.a_head_mps2 - s.a_table_mps2) : Eigen::Vector3d::Constant(NAN), s.vel_mm_s, live_dv_mm_s(),
                         std::sqrt(pvv) / 1000.0, s.cmd_valid, s.cmd_moved);
  r.rest = s.accel_valid && r.det.rest;  // found and reported even when ZUPT is off
  return r;
}

// A ringing standstill — its acceleration not quiet, or its velocity spreading over the
// detector's window beyond what the noise makes of it — is not used sample by sample (its
// swings are correlated) but by the mean velocity over each vibration window. A sine's mean
// over a window at least twice its period is below 0.2 of its rms: 0.3 of the spread is the
// σ of that mean.
void SupportStage::zupt_or_window_mean(const SupportSample& s, RestDecision& r) noexcept {
  if (!(r.rest && !(r.det.quiet && r.det.velocity_spread_mm_s * 1000.0 <= 3.0 * cfg_.model.zupt_sigma_um_s))) {
    ringing_count_ = 0;
    return;
  }
  r.zupt_sigma_um_s = -1.0;
  if (++ringing_count_ % detector_.vibration_window() != 0) return;
  r.mean_update = true;
  r.mean.k = s.k;
  for (int a = 0; a < 3; ++a) r.mean.mean_um_s[a] = r.det.window_mean_mm_s[a] * 1000.0;
  r.mean.sigma_um_s = 0.3 * r.det.vibration_sigma_mm_s * 1000.0;
  r.mean.lag_s = r.det.window_lag_s;
}

// Rest, NBS (an axis whose set-point has not moved since the last rest, Bild 7-8) and the
// start of a move.
std::uint8_t SupportStage::schedule_flags(const SupportSample& s, const RestDecision& r) noexcept {
  std::uint8_t flags = 0;
  if (!s.accel_valid) flags |= fusion::schedule_flag::invalid;
  if (r.rest) {
    flags |= fusion::schedule_flag::rest;
    if (s.cmd_valid) cmd_at_rest_ = s.cmd_mm;
  } else if (cfg_.nbs && s.cmd_valid) {
    for (int a = 0; a < 3; ++a)
      if (std::abs(s.cmd_mm[a] - cmd_at_rest_[a]) < 1e-9) flags |= fusion::nbs_flag(a);
  }
  if (s.k == 0 && s.cmd_valid) cmd_at_rest_ = s.cmd_mm;  // the set-point where the motion starts
  if (s.k > 0 && at_rest_ && !r.rest) flags |= fusion::schedule_flag::move_start;
  return flags;
}

void SupportStage::predict_and_support_velocity(const SupportSample& s, const RestDecision& r, std::uint8_t flags) noexcept {
  const bool move_start = (flags & fusion::schedule_flag::move_start) != 0;
  if (s.k > 0)
    live_.predict(s.gap_samples == 1 ? step_ : fusion::discretise(cfg_.model, static_cast<double>(s.gap_samples) / fs_hz_), move_start, cfg_.model);
  live_.velocity_supports(flags, s.vel_mm_s * 1000.0, cfg_.model, r.zupt_sigma_um_s, cfg_.zupt);
  if (r.mean_update) {
    live_.velocity_mean(r.mean, cfg_.model, cfg_.zupt);
    if (schedule_.velocity_means.size() < schedule_.velocity_means.capacity()) schedule_.velocity_means.push_back(r.mean);
  }
}

// CUPT: every lit PSD strip is a position fix along its axis (recorded always, used when
// CUPT is on).
void SupportStage::position_fixes(const SupportSample& s, const Eigen::Vector3d& vel_corr) noexcept {
  for (std::size_t p = 0; p < psd_.size(); ++p) {
    const supports::PsdReading& r = psd_now_[p];
    if (!r.valid) continue;
    const int ax = psd_[p].axis();
    // The lock-in output lags the spot by its time constant: add τ·v.
    const double fix_um = (psd_[p].centre_mm() + r.u_mm + psd_[p].lockin_tau_s() * vel_corr[ax]) * 1000.0;
    const double model_um = cfg_.model.scale_uncertainty * (s.pos_mm - start_pos_mm_).norm() * 1000.0;
    if (cfg_.cupt) live_.position_fix(ax, s.pos_mm[ax] * 1000.0, fix_um, std::hypot(r.sigma_mm * 1000.0, model_um), cfg_.model);
    if (schedule_.fixes.size() < capacity_) schedule_.fixes.push_back({s.k, ax, fix_um, r.sigma_mm * 1000.0, static_cast<int>(p), model_um});
    else ++fixes_dropped_;
  }
}

void SupportStage::record(std::uint8_t flags, const RestDecision& r) noexcept {
  if (schedule_.flags.size() >= capacity_) return;
  schedule_.flags.push_back(flags);
  schedule_.zupt_sigma_um_s.push_back(static_cast<float>(r.zupt_sigma_um_s));
}

// The sensors' mean at a standstill: their bias there (the drift between rests).
void SupportStage::track_rest_window(const SupportSample& s, const RestDecision& r) noexcept {
  if (r.rest) {
    if (open_.samples == 0) open_.first_index = static_cast<std::int64_t>(s.k);
    open_.last_index = static_cast<std::int64_t>(s.k);
    open_.table_mps2 += s.a_table_mps2;
    open_.head_mps2 += s.a_head_mps2;
    open_.quiet = open_.quiet && r.det.quiet;
    ++open_.samples;
  } else {
    close_rest_window();
  }
  at_rest_ = r.rest;
}

SupportSummary SupportStage::finish(const std::vector<std::int64_t>& idx, std::vector<Eigen::Vector3d>& pos_mm,
                                    std::vector<Eigen::Vector3d>& vel_mm_s, std::vector<Eigen::Vector3d>& sigma_x_um) {
  close_rest_window();
  SupportSummary sum;
  const std::size_t n = std::min({idx.size(), pos_mm.size(), schedule_.flags.size()});
  auto& flags = schedule_.flags;
  flags.resize(n);
  schedule_.zupt_sigma_um_s.resize(n);
  // Hindsight: the velocity is trusted only from zupt_onset_skip_s into a standstill on.
  // A machine settles into its standstill (the position loop takes up its lag over a few
  // time constants, the sensors ring out); the live filter cannot wait, the offline pass
  // can, and a few µm/s taken for zero at the onset would bend the whole move before it.
  namespace sf = fusion::schedule_flag;
  const auto skip = static_cast<std::size_t>(std::llround(cfg_.model.zupt_onset_skip_s * fs_hz_));
  // A standstill that became quiet is used by its quiet samples alone: its window means
  // (kept for a machine that never stops ringing) would count the settling as velocity.
  std::vector<std::pair<std::size_t, std::size_t>> quiet_runs;
  for (std::size_t k = 0; k < n; ++k) {
    if (!(flags[k] & sf::rest) || (k > 0 && (flags[k - 1] & sf::rest))) continue;
    std::size_t e = k;
    while (e + 1 < n && (flags[e + 1] & sf::rest)) ++e;
    // From its first quiet sample on (the position loop may still be taking up its lag
    // while the set-point rests: that is motion, however slow).
    std::size_t q = k;
    while (q <= e && schedule_.zupt_sigma_um_s[q] != 0.0F) ++q;
    for (std::size_t j = q; j <= e && j < q + skip; ++j) schedule_.zupt_sigma_um_s[j] = -1.0F;
    if (q <= e) quiet_runs.push_back({k, e});
  }
  auto& means = schedule_.velocity_means;
  means.erase(std::remove_if(means.begin(), means.end(),
                             [&](const fusion::VelocityMean& v) {
                               for (const auto& r : quiet_runs)
                                 if (v.k >= r.first && v.k <= r.second) return true;
                               return false;
                             }),
              means.end());
  for (std::size_t k = 1; k < n; ++k) {
    flags[k] = static_cast<std::uint8_t>(flags[k] & ~sf::move_start);
    if ((flags[k - 1] & sf::rest) && !(flags[k] & sf::rest)) flags[k] |= sf::move_start;
  }
  // Rest windows in sample indices.
  for (auto w : rests_) {
    w.first_index = idx[std::min(static_cast<std::size_t>(w.first_index), n - 1)];
    w.last_index = idx[std::min(static_cast<std::size_t>(w.last_index), n - 1)];
    sum.rest_windows.push_back(w);
  }
  sum.psd_fixes = schedule_.fixes.size();
  sum.start_bias_sigma_um_s2 = start_bias_sigma_;
  sum.psd_fixes_dropped = fixes_dropped_;
  if (n == 0) return sum;

  std::vector<std::int64_t> index(idx.begin(), idx.begin() + static_cast<std::ptrdiff_t>(n));
  pos_mm.resize(n), vel_mm_s.resize(n);
  fusion::SmootherInput in;
  in.sample_index = &index;
  in.vel_mm_s = &vel_mm_s;
  in.pos_mm = &pos_mm;
  in.schedule = &schedule_;
  in.fs_hz = fs_hz_;
  in.model = cfg_.model;
  in.start_bias_sigma_um_s2 = start_bias_sigma_;
  in.forward_only = !cfg_.smooth;
  fusion::SmootherOutput out = fusion::smooth(in);
  // PSD readings the integration cannot follow — its strip resets, or rejections of more
  // than 5 % — mean the sensor model is off (uncalibrated scale or mounting: the error is
  // then no slowly wandering bias, and pulling the trace to the strips would bend it far
  // between them). The measurement is then fused without them, and says so.
  std::size_t cupt_ok = 0, cupt_bad = 0;
  for (int a = 0; a < 3; ++a) {
    const auto& cupt = out.tally[a][static_cast<int>(fusion::Support::cupt)];
    cupt_ok += cupt.accepted, cupt_bad += cupt.rejected;
  }
  if (schedule_.cupt && cupt_ok + cupt_bad > 0 && (out.resets > 0 || 20 * cupt_bad > cupt_ok + cupt_bad)) {
    sum.psd_disagrees = true;
    sum.psd_rejected = cupt_bad;
    schedule_.cupt = false;
    out = fusion::smooth(in);
    schedule_.cupt = true;
  }
  bool finite = true;
  for (std::size_t k = 0; k < n && finite; ++k) finite = out.dx_um[k].allFinite() && out.dv_um_s[k].allFinite();
  if (!finite) {  // an input the model cannot take (a saturated channel): leave the trace as integrated
    sum.diverged = true;
    sigma_x_um.assign(n, Eigen::Vector3d::Constant(NAN));
    return sum;
  }
  for (std::size_t k = 0; k < n; ++k) {
    pos_mm[k] -= out.dx_um[k] / 1000.0;
    vel_mm_s[k] -= out.dv_um_s[k] / 1000.0;
  }
  sigma_x_um = out.sigma_x_um;
  sum.tally = out.tally;
  sum.resets = out.resets;
  sum.smoothed = cfg_.smooth;
  return sum;
}

}  // namespace eical::dsp
