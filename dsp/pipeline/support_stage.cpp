#include "dsp/pipeline/support_stage.hpp"
#include "dsp/core/float_limits.hpp"
#include "dsp/core/frame_fields.hpp"
#include "dsp/fusion/crossing_fixes.hpp"

#include <algorithm>
#include <cmath>
#include <tuple>

namespace eical::dsp {
namespace {
// A standstill's late part (fusion/bias_steps.hpp): from 0.2 s after it opened (the
// position loop's creep has decayed), in batches of 50 ms for its scatter.
constexpr double kLateSettleS = 0.2;
constexpr double kLateBatchS = 0.05;

constexpr std::size_t kMaxRestWindows = 4096;

// The start's σ on an axis whose strips set its frame: no constraint (a machine is never a
// millimetre off its set-point) that still keeps the filter's numbers near 1.
constexpr double kFreeStartUm = 1000.0;

// Strips this far apart along their axis observe its scale: two readings differ by δs·d.
// One strip length: closer, a strip's own reach over its length sees as much.
constexpr double kScaleSpanMm = 10.0;

// Per axis, the σ (ppm) of the scale as a state: the model's scale uncertainty where the
// strips measuring the axis span kScaleSpanMm along it, else 0 (fusion::ErrorModel).
std::array<double, 3> scale_state_ppm(const std::vector<supports::PsdDecoder>& psd, double scale_uncertainty) {
  std::array<double, 3> lo{}, hi{}, out{};
  std::array<bool, 3> seen{};
  for (const auto& strip : psd) {
    const auto a = static_cast<std::size_t>(strip.axis());
    lo[a] = seen[a] ? std::min(lo[a], strip.centre_mm()) : strip.centre_mm();
    hi[a] = seen[a] ? std::max(hi[a], strip.centre_mm()) : strip.centre_mm();
    seen[a] = true;
  }
  for (std::size_t a = 0; a < 3; ++a)
    if (seen[a] && hi[a] - lo[a] >= kScaleSpanMm) out[a] = scale_uncertainty * 1e6;
  return out;
}

// Per axis, the σ (µs) of the timing as a state: the model's timing uncertainty where a strip
// measures the axis, else 0 (fusion::ErrorModel).
std::array<double, 3> timing_state_us(const std::vector<supports::PsdDecoder>& psd,
                                      const std::array<double, 3>& timing_uncertainty_s) {
  std::array<double, 3> out{};
  for (const auto& strip : psd) {
    const auto a = static_cast<std::size_t>(strip.axis());
    out[a] = timing_uncertainty_s[a] * 1e6;
  }
  return out;
}

}  // namespace

SupportStage::SupportStage(const SupportConfig& config, const Acquisition& acquisition, const std::vector<PsdSpec>& psd,
                           double sensor_noise_var_m2ps4, std::size_t capacity_samples, std::size_t reserve_samples)
    : cfg_(config),
      fs_hz_(acquisition.fs_hz),
      step_(fusion::discretise(config.model, 1.0 / acquisition.fs_hz)),
      detector_(config.standstill, acquisition.fs_hz, acquisition.daq_group_delay_samples, sensor_noise_var_m2ps4),
      capacity_(capacity_samples) {
  for (const auto& s : psd) {
    if (psd_.size() >= static_cast<std::size_t>(kMaxPsd)) break;
    psd_.emplace_back(s, acquisition);
  }
  schedule_.zupt = config.zupt;
  schedule_.cupt = config.cupt;
  if (config.cupt) {
    cfg_.model.scale_state_ppm = scale_state_ppm(psd_, config.model.scale_uncertainty);
    cfg_.model.timing_state_us = timing_state_us(psd_, config.model.timing_uncertainty_s);
  }
  record_way_ = fusion::reads_the_way(cfg_.model);
  if (!config.record) capacity_samples = 0;  // live: the forward filter only, nothing per sample
  capacity_ = capacity_samples;
  // Reserved, not touched: memory is taken as the measurement fills it (the live and the
  // whole-trace pipelines reserve their capacity: no allocation per sample).
  reserve_samples = std::min(reserve_samples, capacity_samples);
  schedule_.flags.reserve(reserve_samples);
  if (config.compact)
    zupt_unused_.reserve(reserve_samples);
  else
    schedule_.zupt_sigma_um_s.reserve(reserve_samples);
  schedule_.fixes.reserve(reserve_samples);
  schedule_.velocity_means.reserve(reserve_samples / 100 + 16);
  gaps_.reserve(reserve_samples);
  support_vel_mm_s_.reserve(reserve_samples);
  fix_pos_mm_.reserve(reserve_samples);
  if (record_way_) schedule_.way_mm.reserve(reserve_samples);
  rests_.reserve(kMaxRestWindows);
  block_len_ = static_cast<std::size_t>(std::max(1.0, std::round(0.02 * acquisition.fs_hz)));
  late_settle_ = static_cast<std::size_t>(std::round(kLateSettleS * acquisition.fs_hz));
  late_batch_len_ = static_cast<std::size_t>(std::max(1.0, std::round(kLateBatchS * acquisition.fs_hz)));
  block_means_.reserve(kMaxRestWindows);
  reset();
}

void SupportStage::reset() noexcept {
  for (auto& d : psd_) d.reset();
  psd_now_ = {};
  detector_.reset();
  schedule_.flags.clear();
  schedule_.zupt_sigma_um_s.clear();
  zupt_unused_.clear();
  schedule_.velocity_means.clear();
  schedule_.fixes.clear();
  gaps_.clear();
  support_vel_mm_s_.clear();
  fix_pos_mm_.clear();
  schedule_.way_mm.clear();
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
  late_batch_sum_.setZero(), late_sum_.setZero(), late_sq_.setZero(), batch_ss_.setZero();
  late_batch_n_ = late_batches_ = batch_dof_ = 0;
  late_quiet_ = true;
  ringing_count_ = 0;
  live_.start(cfg_.model, Eigen::Vector3d::Constant(cfg_.model.bias_step_um_s2));
}

void SupportStage::psd_frame(const Frame& f) noexcept {
  // A source that names the empty electrodes loses only those strips; one that cannot
  // (psd_missing alone) loses them all for this sample.
  for (std::size_t k = 0; k < psd_.size(); ++k) {
    const int e = 2 * static_cast<int>(k);
    const bool missing = frame_flag::psd_electrode_empty(f, e) || frame_flag::psd_electrode_empty(f, e + 1);
    psd_now_[k] = psd_[k].step(f.psd_counts[e], f.psd_counts[e + 1], missing);
  }
}

void SupportStage::rest_sample(const Eigen::Vector3d& a_rel_mps2) noexcept {
  if (!a_rel_mps2.allFinite()) return;
  rest_sum_ += a_rel_mps2;
  rest_sq_ += a_rel_mps2.cwiseProduct(a_rel_mps2);
  ++rest_n_;
  block_sum_ += a_rel_mps2;
  if (++block_n_ == block_len_) {
    if (block_means_.size() < block_means_.capacity())
      block_means_.push_back(block_sum_ / static_cast<double>(block_len_));
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
    start_bias_sigma_ = Eigen::Vector3d::Constant(
        std::sqrt(detector_.noise_var() / std::max<double>(1.0, static_cast<double>(rest_n_))) * 1e6);
  }
  live_.start(cfg_.model, start_bias_sigma_);
  started_ = true;
  at_rest_ = false;
  start_pos_mm_ = frame_ref_mm_ = Eigen::Vector3d::Constant(kNaN);
}

Eigen::Vector3d SupportStage::live_dx_mm() const noexcept {
  return Eigen::Vector3d(live_.axis[0].e[0], live_.axis[1].e[0], live_.axis[2].e[0]) / 1000.0;
}

Eigen::Vector3d SupportStage::live_dv_mm_s() const noexcept {
  return Eigen::Vector3d(live_.axis[0].e[1], live_.axis[1].e[1], live_.axis[2].e[1]) / 1000.0;
}

void SupportStage::close_rest_window() noexcept {
  if (late_batches_ >= 2 && late_quiet_) {
    const auto j = static_cast<double>(late_batches_);
    open_.late_rel_mps2 = late_sum_ / j;
    open_.late_s = j * static_cast<double>(late_batch_len_) / fs_hz_;
    batch_ss_ += late_sq_ - late_sum_.cwiseAbs2() / j;
    batch_dof_ += late_batches_ - 1;
  }
  late_batch_sum_.setZero(), late_sum_.setZero(), late_sq_.setZero();
  late_batch_n_ = late_batches_ = 0;
  late_quiet_ = true;
  if (open_.samples == 0) return;
  open_.table_mps2 /= static_cast<double>(open_.samples);
  open_.head_mps2 /= static_cast<double>(open_.samples);
  if (rests_.size() < kMaxRestWindows)
    rests_.push_back(open_);
  else
    ++rests_dropped_;
  open_ = RestWindow{};
}

// Where the integration is anchored, and how far the strips' frame may sit from that
// anchor on each axis (ErrorModel::start_frame_um): the filter starts with both. The
// strip nearest the start is the frame's reference on its axis: a reading's scale share
// counts from there. Where the strips span an axis (its scale a state) they set its frame
// whatever the program: the set-point at the start is then no reference at all, for the
// machine's error there is what the test measures (a drawn machine's straightness put a
// R150 circle's start 20 µm off its set-point; anchored there within 2 µm, the strip under
// the start contradicted it 100 times, the filter reset and the run lost all its strips).
void SupportStage::anchor_start(const Eigen::Vector3d& pos_mm) noexcept {
  start_pos_mm_ = pos_mm;
  frame_ref_mm_ = pos_mm;
  std::array<double, 3> nearest_mm;
  nearest_mm.fill(kNaN);
  if (cfg_.cupt && cfg_.strips_set_the_frame)
    for (const auto& strip : psd_) {
      const auto a = static_cast<std::size_t>(strip.axis());
      const double d_mm = std::abs(strip.centre_mm() - pos_mm[strip.axis()]);
      if (!(d_mm >= nearest_mm[a])) nearest_mm[a] = d_mm, frame_ref_mm_[strip.axis()] = strip.centre_mm();
    }
  for (int a = 0; a < 3; ++a) {
    const auto i = static_cast<std::size_t>(a);
    cfg_.model.start_frame_um[i] =
        fusion::scale_is_a_state(cfg_.model, a)
            ? kFreeStartUm
            : (std::isfinite(nearest_mm[i]) ? cfg_.model.scale_uncertainty * nearest_mm[i] * 1000.0 : 0.0);
    live_.axis[a].P(0, 0) = fusion::initial_covariance(cfg_.model, a, 0.0)(0, 0);
  }
}

void SupportStage::step(const SupportSample& s) noexcept {
  if (s.k == 0) anchor_start(s.pos_mm);
  // The velocity as the live filter corrects it before this sample's update (the lock-in's lag).
  const Eigen::Vector3d vel_corr_mm_s = s.vel_mm_s - live_dv_mm_s();
  RestDecision r = find_rest(s);
  zupt_or_window_mean(s, r);
  const std::uint8_t flags = schedule_flags(s, r);
  predict_and_support_velocity(s, r, flags);
  position_fixes(s, vel_corr_mm_s);
  record(s, flags, r);
  track_rest_window(s, r);
}

SupportStage::RestDecision SupportStage::find_rest(const SupportSample& s) noexcept {
  double pvv = 0.0;
  for (const auto& f : live_.axis) pvv = std::max(pvv, f.P(1, 1));
  RestDecision r;
  r.det =
      detector_.step(s.accel_valid ? Eigen::Vector3d(s.a_head_mps2 - s.a_table_mps2) : Eigen::Vector3d::Constant(kNaN),
                     s.vel_mm_s, live_dv_mm_s(), std::sqrt(pvv) / 1000.0, s.cmd_valid, s.cmd_moved);
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

void SupportStage::predict_and_support_velocity(const SupportSample& s, const RestDecision& r,
                                                std::uint8_t flags) noexcept {
  const bool move_start = (flags & fusion::schedule_flag::move_start) != 0;
  if (s.k > 0)
    live_.predict(
        s.gap_samples == 1 ? step_ : fusion::discretise(cfg_.model, static_cast<double>(s.gap_samples) / fs_hz_),
        move_start, cfg_.model);
  live_.velocity_supports(flags, s.vel_mm_s * 1000.0, cfg_.model, r.zupt_sigma_um_s, cfg_.zupt);
  if (r.mean_update) {
    live_.velocity_mean(r.mean, cfg_.model, cfg_.zupt);
    if (cfg_.record && (schedule_.velocity_means.size() < schedule_.velocity_means.capacity() || capacity_ == SIZE_MAX))
      schedule_.velocity_means.push_back(r.mean);
  }
}

// CUPT: every lit PSD strip is a position fix along its axis (recorded always, used when
// CUPT is on).
void SupportStage::position_fixes(const SupportSample& s, const Eigen::Vector3d& vel_corr_mm_s) noexcept {
  for (std::size_t p = 0; p < psd_.size(); ++p) {
    const supports::PsdReading& r = psd_now_[p];
    if (!r.valid) continue;
    const int ax = psd_[p].axis();
    // The lock-in output lags the spot by its time constant: add τ·v.
    const double fix_um = (psd_[p].centre_mm() + r.u_mm + psd_[p].lockin_tau_s() * vel_corr_mm_s[ax]) * 1000.0;
    // The scale's share: along the strip's axis from the frame's reference (anchor_start),
    // or none where the filter keeps the scale as a state; across it (the mounting) from
    // the start.
    Eigen::Vector3d way_mm = s.pos_mm - start_pos_mm_;
    const double along_mm = way_mm[ax];
    const bool scale_state = fusion::scale_is_a_state(cfg_.model, ax);
    way_mm[ax] = scale_state ? 0.0 : s.pos_mm[ax] - frame_ref_mm_[ax];
    const double model_um = cfg_.model.scale_uncertainty * way_mm.norm() * 1000.0;
    if (cfg_.cupt)
      live_.position_fix(ax, s.pos_mm[ax] * 1000.0, fix_um, std::hypot(r.sigma_mm * 1000.0, model_um), cfg_.model,
                         along_mm, s.vel_mm_s[ax]);
    if (schedule_.fixes.size() < capacity_) {
      schedule_.fixes.push_back(
          {s.k, ax, fix_um, r.sigma_mm * 1000.0, static_cast<int>(p), model_um, along_mm, s.vel_mm_s[ax]});
      fix_pos_mm_.push_back(s.pos_mm[ax]);
    } else if (cfg_.record) {
      ++fixes_dropped_;
    }
  }
}

void SupportStage::record(const SupportSample& s, std::uint8_t flags, const RestDecision& r) noexcept {
  if (schedule_.flags.size() >= capacity_) return;  // within the reserve: no allocation
  schedule_.flags.push_back(flags);
  if (cfg_.compact)
    zupt_unused_.push_back(r.zupt_sigma_um_s < 0.0);  // −1 or 0 (see smooth_track())
  else
    schedule_.zupt_sigma_um_s.push_back(static_cast<float>(r.zupt_sigma_um_s));
  if (s.k > 0 && s.gap_samples != 1) gaps_.emplace_back(s.k, s.gap_samples);
  if (fusion::reads_velocity(flags)) support_vel_mm_s_.push_back(s.vel_mm_s);
  if (record_way_) schedule_.way_mm.push_back((s.pos_mm - start_pos_mm_).cast<float>());
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
    if (open_.samples > late_settle_ && s.accel_valid) {
      late_quiet_ = late_quiet_ && r.det.quiet;
      late_part_sample(s.a_head_mps2 - s.a_table_mps2);
    }
  } else {
    close_rest_window();
  }
  at_rest_ = r.rest;
}

void SupportStage::late_part_sample(const Eigen::Vector3d& a_rel_mps2) noexcept {
  if (!a_rel_mps2.allFinite()) return;
  late_batch_sum_ += a_rel_mps2;
  if (++late_batch_n_ < late_batch_len_) return;
  const Eigen::Vector3d b = late_batch_sum_ / static_cast<double>(late_batch_len_);
  late_sum_ += b, late_sq_ += b.cwiseAbs2();
  ++late_batches_;
  late_batch_sum_.setZero();
  late_batch_n_ = 0;
}

// The bias jump at a move start, from the standstills' late means (fusion/bias_steps.hpp).
void SupportStage::measure_bias_step(SupportSummary& sum) const {
  std::vector<fusion::StandstillMean> means;
  for (const RestWindow& w : rests_)
    if (w.late_s > 0.0)
      // t: the middle of the late part, which ends with the window.
      means.push_back(
          {static_cast<double>(w.last_index + 1) / fs_hz_ - 0.5 * w.late_s, w.late_s, w.late_rel_mps2 * 1e6});
  const double batch_var_um2_s4 =
      batch_dof_ > 0 ? batch_ss_.sum() / 3.0 / static_cast<double>(batch_dof_) * 1e12 : kNaN;
  sum.bias_step = fusion::measure_bias_step(means, start_bias_sigma_, batch_var_um2_s4, batch_dof_,
                                            static_cast<double>(late_batch_len_) / fs_hz_,
                                            cfg_.model.accel_noise_um_s2_rthz, cfg_.model.bias_walk_um_s2_rts);
  // Only ever wider: standstills that jump more than the model allows (the point estimate
  // beyond it) would make the smoother too sure of the bias. Narrower is not taken yet: on
  // the simulator's positioning tests (no jumps; 0.7–1.3 µg measured, the standstill means
  // scattering beyond their 50 ms batches) it halved U(A) but doubled U(B), for a cause not
  // yet understood.
  const double model_um_s2 = cfg_.model.bias_step_um_s2;
  const bool jumps_more = sum.bias_step.measured && sum.bias_step.excess_um2_s4 > model_um_s2 * model_um_s2;
  sum.bias_step_um_s2 = jumps_more ? sum.bias_step.step_um_s2 : model_um_s2;
  sum.bias_step_from_standstills = jumps_more;
}

SupportSummary SupportStage::refine(std::size_t n, const std::function<std::int64_t(std::size_t)>& index_at) {
  close_rest_window();
  SupportSummary sum;
  auto& flags = schedule_.flags;
  n = std::min(n, flags.size());
  // Samples beyond n (a trace shorter than the schedule) take their velocities along.
  std::size_t reads = 0;
  for (std::size_t k = 0; k < n; ++k) reads += fusion::reads_velocity(flags[k]) ? 1 : 0;
  support_vel_mm_s_.resize(std::min(reads, support_vel_mm_s_.size()));
  while (!gaps_.empty() && gaps_.back().first >= n) gaps_.pop_back();
  flags.resize(n);
  if (schedule_.way_mm.size() > n) schedule_.way_mm.resize(n);
  if (cfg_.compact)
    zupt_unused_.resize(n);
  else
    schedule_.zupt_sigma_um_s.resize(n);
  auto used = [&](std::size_t k) { return cfg_.compact ? !zupt_unused_[k] : schedule_.zupt_sigma_um_s[k] == 0.0F; };
  auto unuse = [&](std::size_t k) {
    if (cfg_.compact)
      zupt_unused_[k] = true;
    else
      schedule_.zupt_sigma_um_s[k] = -1.0F;
  };
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
    while (q <= e && !used(q)) ++q;
    for (std::size_t j = q; j <= e && j < q + skip; ++j) unuse(j);
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
    if (n == 0) break;
    w.first_index = index_at(std::min(static_cast<std::size_t>(w.first_index), n - 1));
    w.last_index = index_at(std::min(static_cast<std::size_t>(w.last_index), n - 1));
    sum.rest_windows.push_back(w);
  }
  sum.psd_fixes = schedule_.fixes.size();
  sum.start_bias_sigma_um_s2 = start_bias_sigma_;
  sum.start_frame_um = cfg_.model.start_frame_um;
  sum.scale_state_ppm = cfg_.model.scale_state_ppm;
  sum.timing_state_us = cfg_.model.timing_state_us;
  sum.psd_fixes_dropped = fixes_dropped_;
  measure_bias_step(sum);
  return sum;
}

// PSD readings the integration cannot follow — its strip resets, or rejections of more
// than 5 % — mean the sensor model is off (uncalibrated scale or mounting: the error is
// then no slowly wandering bias, and pulling the trace to the strips would bend it far
// between them). First their slope goes: a crossing's readings imply the velocity, which
// the scale errs by scale × v, and a standstill right after contradicts it
// (fusion/crossing_fixes.hpp); each crossing then gives one position. When even those
// disagree, the measurement is fused without them, and says so.
void SupportStage::fuse_psd(SmoothedCorrection& c, SupportSummary& sum, bool hand_over,
                            const fusion::SmootherSettings& st, fusion::SegmentSink* sink) {
  c.smoother =
      std::make_unique<fusion::CheckpointedSmoother>(c.track, st, fusion::CheckpointedSmoother::kSegment, sink);
  std::size_t rejected = 0;  // by the smoother over every reading: what the summary reports
  const auto disagrees = [&c](std::size_t* rejected_out) {
    std::size_t ok = 0, bad = 0;
    for (int a = 0; a < 3; ++a) {
      const auto& cupt = c.smoother->tally()[a][static_cast<int>(fusion::Support::cupt)];
      ok += cupt.accepted, bad += cupt.rejected;
    }
    if (rejected_out) *rejected_out = bad;
    return c.schedule.cupt && ok + bad > 0 && (c.smoother->resets() > 0 || 20 * bad > ok + bad);
  };
  const auto resmooth = [&](const fusion::SmootherSettings& settings) {
    c.smoother =
        std::make_unique<fusion::CheckpointedSmoother>(c.track, settings, fusion::CheckpointedSmoother::kSegment, sink);
  };
  bool disagree = disagrees(&rejected);
  if (disagree) {
    std::vector<fusion::PositionFix> fixes = c.schedule.fixes;
    std::vector<double> fix_pos_mm = c.track.fix_pos_mm;
    fusion::merge_crossings(fixes, fix_pos_mm, cfg_.model.scale_uncertainty,
                            static_cast<std::size_t>(std::ceil(fusion::kCrossingGapS * fs_hz_)),
                            cfg_.model.scale_state_ppm);
    if (fixes.size() < c.schedule.fixes.size()) {
      std::swap(fixes, c.schedule.fixes), std::swap(fix_pos_mm, c.track.fix_pos_mm);
      resmooth(st);
      disagree = disagrees(nullptr);
      if (disagree) {  // as they were: the run's record of what the strips read
        std::swap(fixes, c.schedule.fixes), std::swap(fix_pos_mm, c.track.fix_pos_mm);
      } else {
        sum.psd_crossings_merged = true;
        if (!hand_over) schedule_.fixes = c.schedule.fixes, fix_pos_mm_ = c.track.fix_pos_mm;  // what the draws model
      }
    }
  }
  if (disagree) {
    sum.psd_disagrees = true;
    sum.psd_rejected = rejected;
    sum.start_frame_um = {};  // no strip's frame to meet: the start anchors alone
    c.schedule.cupt = false;  // for good: segments are recomputed from this schedule
    fusion::SmootherSettings without = st;
    without.model.start_frame_um = {};
    resmooth(without);
  }
}

std::unique_ptr<SmoothedCorrection> SupportStage::smooth_track(std::size_t n, SupportSummary& sum, bool hand_over,
                                                               fusion::SegmentSink* sink) {
  auto c = std::make_unique<SmoothedCorrection>();
  c->track.n = n;
  c->track.schedule = &c->schedule;
  if (hand_over) {  // the stage is done with them (streamed analysis): no second copy
    c->schedule = std::move(schedule_);
    c->track.gaps = std::move(gaps_);
    c->track.support_vel_mm_s = std::move(support_vel_mm_s_);
    c->track.fix_pos_mm = std::move(fix_pos_mm_);
    // ZUPT σ per sample is 0 or −1 (step() and refine() write nothing else): as bits.
    auto& zs = c->schedule.zupt_sigma_um_s;
    if (cfg_.compact) {
      c->track.zupt_unused = std::move(zupt_unused_);
    } else if (std::all_of(zs.begin(), zs.end(), [](float z) { return z == 0.0F || z == -1.0F; })) {
      c->track.zupt_unused.resize(zs.size());
      for (std::size_t k = 0; k < zs.size(); ++k) c->track.zupt_unused[k] = zs[k] == -1.0F;
      std::vector<float>().swap(zs);
    }
  } else {
    c->schedule = schedule_;
    c->track.zupt_unused = zupt_unused_;
    c->track.gaps = gaps_;
    c->track.support_vel_mm_s = support_vel_mm_s_;
    c->track.fix_pos_mm = fix_pos_mm_;
  }
  fusion::SmootherSettings st;
  st.fs_hz = fs_hz_, st.model = cfg_.model, st.start_bias_sigma_um_s2 = start_bias_sigma_;
  st.model.bias_step_um_s2 = sum.bias_step_um_s2;
  st.forward_only = !cfg_.smooth;
  st.parallel = cfg_.parallel;
  fuse_psd(*c, sum, hand_over, st, sink);
  c->apply = c->smoother->finite();
  if (!c->apply) {  // an input the model cannot take (a saturated channel): leave the trace as integrated
    sum.diverged = true;
    return c;
  }
  sum.tally = c->smoother->tally();
  sum.resets = c->smoother->resets();
  for (int a = 0; a < 3; ++a) {  // what the strips showed (none when they were dropped)
    const auto i = static_cast<std::size_t>(a);
    if (!c->schedule.cupt) continue;
    if (fusion::scale_is_a_state(sum.scale_state_ppm, a))
      std::tie(sum.scale_ppm[i], sum.scale_sigma_ppm[i]) = c->smoother->scale_ppm(a);
    if (fusion::timing_is_a_state(cfg_.model, a))
      std::tie(sum.timing_us[i], sum.timing_sigma_us[i]) = c->smoother->timing_us(a);
  }
  sum.smoothed = cfg_.smooth;
  return c;
}

SupportSummary SupportStage::finish(const std::vector<std::int64_t>& sample_index, std::vector<Eigen::Vector3d>& pos_mm,
                                    std::vector<Eigen::Vector3d>& vel_mm_s, std::vector<Eigen::Vector3d>& sigma_x_um) {
  const std::size_t n = std::min({sample_index.size(), pos_mm.size(), schedule_.flags.size()});
  SupportSummary sum = refine(n, [&](std::size_t k) { return sample_index[k]; });
  if (n == 0) return sum;
  pos_mm.resize(n), vel_mm_s.resize(n);
  const std::unique_ptr<SmoothedCorrection> c = smooth_track(n, sum, false);
  if (!c->apply) {
    sigma_x_um.assign(n, Eigen::Vector3d::Constant(kNaN));
    return sum;
  }
  sigma_x_um.resize(n);
  fusion::SmoothedSegment seg;
  for (std::size_t j = 0; j < c->smoother->segments(); ++j) {
    c->smoother->segment(j, seg);
    for (std::size_t i = 0; i < seg.size(); ++i) {
      const std::size_t k = seg.first + i;
      pos_mm[k] -= seg.dx_um[i] / 1000.0;
      vel_mm_s[k] -= seg.dv_um_s[i] / 1000.0;
      sigma_x_um[k] = seg.sigma_x_um[i];
    }
  }
  return sum;
}

SupportSummary SupportStage::finish_track(std::size_t samples, const std::function<std::int64_t(std::size_t)>& index_at,
                                          std::unique_ptr<SmoothedCorrection>& correction, fusion::SegmentSink* sink) {
  SupportSummary sum = refine(samples, index_at);
  correction.reset();
  if (schedule_.flags.empty()) return sum;
  correction = smooth_track(schedule_.flags.size(), sum, true, sink);
  return sum;
}

std::pair<Eigen::Vector3d, std::size_t> support_velocity_sum(const std::vector<std::uint8_t>& flags,
                                                             const std::vector<Eigen::Vector3d>& support_vel_mm_s,
                                                             std::size_t first, std::size_t last) {
  Eigen::Vector3d v = Eigen::Vector3d::Zero();
  std::size_t count = 0, next = 0;
  for (std::size_t k = 0; k < flags.size() && k <= last; ++k) {
    if (!fusion::reads_velocity(flags[k])) continue;
    if (k >= first && next < support_vel_mm_s.size()) v += support_vel_mm_s[next], ++count;
    ++next;
  }
  return {v, count};
}

std::int64_t SupportStage::trace_index(std::int64_t first_index, std::size_t k) const noexcept {
  std::int64_t idx = first_index + static_cast<std::int64_t>(k);
  for (const auto& [p, g] : gaps_) {
    if (p > k) break;
    idx += g - 1;
  }
  return idx;
}

std::int64_t SmoothedCorrection::sample_index_of(std::int64_t first_index, std::size_t k) const noexcept {
  std::int64_t idx = first_index + static_cast<std::int64_t>(k);
  for (const auto& [p, g] : track.gaps) {
    if (p > k) break;
    idx += g - 1;
  }
  return idx;
}

std::size_t SmoothedCorrection::position_of(std::int64_t first_index, std::int64_t sample_index) const noexcept {
  std::int64_t skipped = 0;  // sample indices the lost frames took before the sample
  for (const auto& [p, g] : track.gaps) {
    if (first_index + static_cast<std::int64_t>(p) + skipped + (g - 1) > sample_index) break;
    skipped += g - 1;
  }
  return static_cast<std::size_t>(std::max<std::int64_t>(0, sample_index - first_index - skipped));
}

}  // namespace eical::dsp
