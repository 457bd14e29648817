#include "dsp/health/channel_health.hpp"

#include "dsp/core/frame_fields.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>

namespace eical::dsp::health {
namespace {

// A constant stretch is stuck when noise would make one this long less often than this per
// sample (not once in 10^9 samples).
constexpr double kStuckFalseRate = 1e-15;
// The channel may be this much quieter than its data sheet before a constant stretch of it
// counts as plausible noise.
constexpr double kStuckNoiseMargin = 4.0;
// Dead: σ at rest below this fraction of the data sheet's, over at least this many samples
// (the variance then known to ±15 %).
constexpr double kDeadSigmaRatio = 0.1;
constexpr std::int64_t kDeadMinRestSamples = 100;

// The shortest constant stretch of a channel with the data sheet's σ (counts) read in steps
// of `step` counts that noise makes less likely than kStuckFalseRate: two samples are
// equal with p = erf(0.5 / (2σ')), σ' the margined σ and the rounding, in steps.
std::int64_t stuck_length(double sigma_counts, double step_counts) {
  const double quiet = sigma_counts / kStuckNoiseMargin / step_counts;
  const double sd = std::sqrt(2.0) * std::sqrt(quiet * quiet + 1.0 / 12.0);  // σ of a difference
  const double p = std::min(0.9, std::erf(0.5 / (sd * std::sqrt(2.0))));
  return 1 + static_cast<std::int64_t>(std::ceil(std::log(kStuckFalseRate) / std::log(p)));
}

// A simulated run whose truth.toml gives every sensor no noise at all (the simulator's noise
// off, for tests of the deterministic signal): a constant stretch is its signal there.
bool noise_free_simulation(const Run& run) {
  if (!run.truth_toml) return false;
  const std::string& t = *run.truth_toml;
  const std::string key = "\nnoise_ug_per_rthz = ";
  int sensors = 0;
  for (auto p = t.find(key); p != std::string::npos; p = t.find(key, p + 1), ++sensors)
    if (std::strtod(t.c_str() + p + key.size(), nullptr) != 0.0) return false;
  return sensors > 0;
}

}  // namespace

std::string channel_name(int c) {
  static const char* const accel[kAccelChannels] = {"table_ax", "table_ay", "table_az",
                                                    "head_ax",  "head_ay",  "head_az"};
  if (is_accel(c)) return accel[c];
  if (c < 0 || c >= kChannels) return "recording";
  const int k = (c - kAccelChannels) / 2;
  return "psd" + std::to_string(k) + ((c - kAccelChannels) % 2 == 0 ? "_i1" : "_i2");
}

const char* fault_code(Fault f) {
  switch (f) {
    case Fault::empty: return "empty";
    case Fault::missing: return "missing";
    case Fault::stuck: return "stuck";
    case Fault::dead: return "dead";
    case Fault::clipped: return "clipped";
    case Fault::truncated: return "truncated";
  }
  return "missing";
}

void ChannelHealth::Spans::add(std::int64_t index) noexcept {
  if (open_first < 0) open_first = index;
  open_last = index;
  ++open_n;
}

void ChannelHealth::Spans::close() noexcept {
  if (open_first < 0) return;
  if (first < 0) first = open_first;
  last = open_last;
  samples += open_n;
  ++spans;
  open_first = open_last = -1, open_n = 0;
}

ChannelHealth::ChannelHealth(const Run& run)
    : fs_hz_(run.meta.acquisition.fs_hz),
      noise_free_(noise_free_simulation(run)),
      clip_high_(std::ldexp(1.0, run.meta.acquisition.adc_bits - 1) - 1.0),
      clip_low_(-std::ldexp(1.0, run.meta.acquisition.adc_bits - 1)) {
  const RunMeta& meta = run.meta;
  const double quantisation = 1.0 / 12.0;  // variance of rounding to counts
  for (int c = 0; c < kChannels; ++c) {
    double sigma = 0.0;
    if (is_accel(c)) {
      const SensorSpec& s = meta.sensors[c / 3];
      ch_[c].active = meta.sensor_present[c / 3];
      // σ per sample n·√fs (two-sided density, run-format.md), g → V → counts.
      sigma = s.noise_ug_per_rthz * 1e-6 * std::sqrt(fs_hz_) * std::abs(s.k1_v_per_g[c % 3]) /
              meta.acquisition.adc_lsb_volt;
    } else {
      ch_[c].active = c - kAccelChannels < 2 * run.channels.psd_count;
    }
    if (!std::isfinite(sigma)) sigma = 0.0;
    sigma_counts_[c] = sigma;
    noise_counts_[c] = std::sqrt(sigma * sigma + quantisation);
    stuck_samples_[c] = stuck_length(sigma, 1.0);
  }
  if (meta.setpoint && meta.setpoint->servo_rate_hz > 0.0)
    servo_hold_samples_ = std::max<std::int64_t>(1, std::llround(std::ceil(fs_hz_ / meta.setpoint->servo_rate_hz)));
}

void ChannelHealth::end_same_run(Channel& ch) noexcept {
  const bool at_limit = ch.last >= clip_high_ || ch.last <= clip_low_;  // clipped, not stuck
  if (ch.same_n > 0 && !at_limit) {
    const std::int64_t c = &ch - ch_;
    // At the channel's own resolution (an imported MEMS chip's counts come in steps of its
    // LSB): longer than at single counts, so only a stretch that long is looked at again.
    if (ch.same_n >= stuck_samples_[c] && !noise_free_ &&
        ch.same_n >= stuck_length(sigma_counts_[c], static_cast<double>(std::max<std::int64_t>(1, ch.min_step)))) {
      ch.stuck.open_first = ch.same_first, ch.stuck.open_last = ch.same_last, ch.stuck.open_n = ch.same_n;
      ch.stuck.close();
      if (ch.same_n > ch.longest_stuck) ch.longest_stuck = ch.same_n, ch.stuck_value = ch.last;
    }
  }
  ch.same_first = ch.same_last = -1, ch.same_n = 0;
}

void ChannelHealth::sample(int c, bool missing, std::int32_t counts, std::int64_t index, bool rest) noexcept {
  Channel& ch = ch_[c];
  if (missing) {
    ch.missing.add(index);
    ch.clipped.close();
    end_same_run(ch);
    ch.has_last = false;
    return;
  }
  ch.missing.close();
  if (counts >= clip_high_ || counts <= clip_low_)
    ch.clipped.add(index);
  else
    ch.clipped.close();
  if (ch.has_last && counts == ch.last) {
    ch.same_last = index, ++ch.same_n;
  } else {
    if (ch.has_last) {
      const std::int64_t step = std::abs(static_cast<std::int64_t>(counts) - ch.last);
      ch.min_step = ch.min_step == 0 ? step : std::min(ch.min_step, step);
    }
    end_same_run(ch);
    ch.same_first = ch.same_last = index, ch.same_n = 1;
  }
  ch.has_last = true, ch.last = counts;
  if (rest && is_accel(c)) {  // Welford: the bias and gravity are large, their noise small
    ++ch.rest_n;
    const double d = static_cast<double>(counts) - ch.rest_mean;
    ch.rest_mean += d / static_cast<double>(ch.rest_n);
    ch.rest_m2 += d * (static_cast<double>(counts) - ch.rest_mean);
  }
}

void ChannelHealth::frame(const Frame& f) noexcept {
  if (first_index_ < 0) first_index_ = f.sample_index;
  last_index_ = f.sample_index;
  ++frames_;
  // The rest window: from M101 (or the first sample) to the set-point's first motion.
  if (f.trigger == trigger::program_start) {
    saw_start_ = true;
    if (rest_) {
      for (auto& ch : ch_) ch.rest_n = 0, ch.rest_mean = ch.rest_m2 = 0.0;
      rest_first_ = -1;
    }
  }
  if (f.trigger == trigger::program_end) saw_end_ = true;
  const bool cmd_ok = !(f.flags & frame_flag::cmd_missing) && std::isfinite(f.cmd_mm[0]) &&
                      std::isfinite(f.cmd_mm[1]) && std::isfinite(f.cmd_mm[2]);
  if (cmd_ok) {
    if (has_cmd_ && (f.cmd_mm[0] != prev_cmd_[0] || f.cmd_mm[1] != prev_cmd_[1] || f.cmd_mm[2] != prev_cmd_[2])) {
      rest_ = false;
      last_move_ = f.sample_index;
    }
    std::copy(f.cmd_mm, f.cmd_mm + 3, prev_cmd_);
    has_cmd_ = true;
  }
  if (rest_) {
    if (rest_first_ < 0) rest_first_ = f.sample_index;
    rest_last_ = f.sample_index;
  }
  // A missing field: the one named, else every field of its sensor (or of the frame).
  const bool any_sensor = (f.flags & (frame_flag::table_missing | frame_flag::head_missing)) != 0;
  for (int c = 0; c < kAccelChannels; ++c) {
    if (!ch_[c].active) continue;
    const int s = c / 3;
    const bool named = (f.flags & frame_flag::sensor_fields_missing(s)) != 0;
    const bool missing = named ? (f.flags & frame_flag::accel_field_missing(c)) != 0
                               : (f.flags & frame_flag::sensor_missing(s)) != 0 ||
                                     ((f.flags & frame_flag::accel_missing) && !any_sensor);
    sample(c, missing, f.accel_counts[c], f.sample_index, rest_);
  }
  for (int c = kAccelChannels; c < kChannels; ++c) {
    if (!ch_[c].active) continue;
    const int e = c - kAccelChannels;
    sample(c, frame_flag::psd_electrode_empty(f, e), f.psd_counts[e], f.sample_index, false);
  }
}

std::vector<Finding> ChannelHealth::finish() {
  std::vector<Finding> out;
  if (frames_ == 0) return out;
  auto span_finding = [&](Fault fault, int c, const Spans& s, double value) {
    Finding x;
    x.fault = fault, x.channel = c;
    x.from_s = seconds(s.first), x.to_s = seconds(s.last);
    x.samples = s.samples, x.spans = s.spans, x.value = value;
    out.push_back(x);
  };
  for (int c = 0; c < kChannels; ++c) {
    Channel& ch = ch_[c];
    if (!ch.active) continue;
    ch.missing.close(), ch.clipped.close();
    end_same_run(ch);
    if (ch.missing.samples == frames_) {  // nothing else to say about a channel never there
      span_finding(Fault::empty, c, ch.missing, 0.0);
      continue;
    }
    if (ch.missing.samples > 0) span_finding(Fault::missing, c, ch.missing, 0.0);
    if (ch.stuck.samples > 0) span_finding(Fault::stuck, c, ch.stuck, static_cast<double>(ch.stuck_value));
    if (ch.clipped.samples > 0) span_finding(Fault::clipped, c, ch.clipped, 0.0);
    // Dead: a flat line at rest that is not one stuck value over that window already.
    const bool stuck_at_rest = ch.stuck.samples > 0 && ch.stuck.first <= rest_first_ && ch.stuck.last >= rest_last_;
    if (is_accel(c) && !noise_free_ && noise_counts_[c] > 0.0 && ch.rest_n >= kDeadMinRestSamples && !stuck_at_rest) {
      const double sigma = std::sqrt(ch.rest_m2 / static_cast<double>(ch.rest_n - 1));
      if (sigma < kDeadSigmaRatio * noise_counts_[c]) {
        Spans rest;
        rest.first = rest_first_, rest.last = rest_last_, rest.samples = ch.rest_n, rest.spans = 1;
        span_finding(Fault::dead, c, rest, sigma / noise_counts_[c]);
      }
    }
  }
  if (saw_start_ && !saw_end_) {
    Finding x;
    x.fault = Fault::truncated;
    x.from_s = x.to_s = seconds(last_index_);
    x.samples = 0;
    x.set_point_moving = last_move_ >= 0 && last_index_ - last_move_ < servo_hold_samples_;
    out.push_back(x);
  }
  return out;
}

std::vector<Finding> check_channels(const Run& run) {
  ChannelHealth h(run);
  for (const Frame& f : run.frames) h.frame(f);
  return h.finish();
}

}  // namespace eical::dsp::health
