#include "dsp/model/run_residuals.hpp"

#include "dsp/core/axes.hpp"
#include "dsp/core/error.hpp"
#include "dsp/core/float_limits.hpp"
#include "dsp/core/interpolate.hpp"

#include <algorithm>
#include <cmath>

namespace eical::dsp::model {
namespace {

// Held out of the fits: every other quarter second. Short blocks keep both sets balanced
// over the axes a program moves in turn (a rectangle's sides alternate x and y: holding
// out every other side would fit x and predict y).
constexpr double kHeldOutBlockS = 0.25;

// A channel's rows as they are added, into its vectors once complete.
struct ChannelRows {
  Channel& channel;
  std::vector<double> r, s;

  void add(int sample, int axis, double r_um, double sigma_um) {
    channel.sample.push_back(sample), channel.axis.push_back(axis);
    r.push_back(r_um), s.push_back(sigma_um);
  }
  void finish() {
    channel.residual_um = Eigen::Map<const Eigen::VectorXd>(r.data(), static_cast<Eigen::Index>(r.size()));
    channel.sigma_um = Eigen::Map<const Eigen::VectorXd>(s.data(), static_cast<Eigen::Index>(s.size()));
  }
};

// The pipeline with the nominal model: ZUPT and smoother, no PSD fixes.
Measurement nominal_measurement(const Run& run) {
  PipelineConfig cfg = pipeline_config(run.meta, run.frames.size());
  cfg.keep_raw = true;
  cfg.cupt = false;  // the strips are a reference here
  cfg.nbs = run.meta.program.kind == ProgramKind::rectangle;
  Pipeline pipe(cfg);
  for (const auto& f : run.frames) pipe.step(f);
  return pipe.finish();
}

// The decimated samples (1 kHz): every step-th of the aligned trace. Returns the step.
std::size_t decimate(RunResiduals& d) {
  const Measurement& m = d.measurement;
  const std::size_t n_full = m.sample_index.size();
  const auto step = static_cast<std::size_t>(std::max(1.0, std::round(m.fs_hz / 1000.0)));
  d.dt_s = static_cast<double>(step) / m.fs_hz;
  for (std::size_t k = 0; k < n_full; k += step) d.trace.push_back(k);
  d.n = static_cast<int>(d.trace.size());
  return step;
}

// The set-point's velocity and acceleration at the full rate (mm/s, mm/s²).
struct SetPointRates {
  std::vector<Eigen::Vector3d> v, a;
};

// Central differences over one decimation step (a set-point printed to 1 nm has second
// differences of 100 mm/s² at 10 kHz; over ten samples a hundredth of that), at the edges
// over what there is.
SetPointRates set_point_rates(const Measurement& m, std::size_t step) {
  const std::size_t n_full = m.sample_index.size();
  const auto q = static_cast<std::ptrdiff_t>(step);
  SetPointRates out{std::vector<Eigen::Vector3d>(n_full, Eigen::Vector3d::Zero()),
                    std::vector<Eigen::Vector3d>(n_full, Eigen::Vector3d::Zero())};
  const double hq = static_cast<double>(q) / m.fs_hz;
  for (std::size_t k = 0; k < n_full; ++k) {
    const auto lo = static_cast<std::size_t>(std::max<std::ptrdiff_t>(0, static_cast<std::ptrdiff_t>(k) - q));
    const auto hi = std::min(n_full - 1, k + static_cast<std::size_t>(q));
    if (hi - k < static_cast<std::size_t>(q) || k - lo < static_cast<std::size_t>(q))
      continue;  // the ends stay at rest
    out.v[k] = (m.cmd_mm[hi] - m.cmd_mm[lo]) / (2.0 * hq);
    out.a[k] = (m.cmd_mm[hi] - 2.0 * m.cmd_mm[k] + m.cmd_mm[lo]) / (hq * hq);
  }
  return out;
}

// The measured acceleration averaged over each decimation step of q samples (a boxcar: what
// lies above the decimated Nyquist folds back less).
double boxcar_at(const std::vector<Eigen::Vector3d>& x, double pos, int a, std::ptrdiff_t q) {
  if (q <= 1) return interpolate_at(x, pos, a);
  double sum = 0.0;
  for (std::ptrdiff_t j = -q / 2; j < q - q / 2; ++j) sum += interpolate_at(x, pos + static_cast<double>(j), a);
  return sum / static_cast<double>(q);
}

// Decimated kinematics on the set-point's time: set-point, its rates, the pipeline's path
// and the measured relative acceleration (read at the same moment in the sensors' time).
void decimated_kinematics(const SetPointRates& rates, std::size_t step, RunResiduals& d) {
  const Measurement& m = d.measurement;
  const Eigen::Index n = d.n;
  const auto q = static_cast<std::ptrdiff_t>(step);
  d.cmd.resize(n, 3), d.v_cmd.resize(n, 3), d.a_cmd.resize(n, 3), d.x_meas.resize(n, 3), d.v_meas.resize(n, 3),
      d.a_meas.resize(n, 3);
  d.t_s.resize(n);
  for (Eigen::Index s = 0; s < n; ++s) {
    const std::size_t k = d.trace[static_cast<std::size_t>(s)];
    const double ks = static_cast<double>(k) + d.delay_samples;  // the same moment in the sensors' time
    for (int a = 0; a < 3; ++a) {
      d.cmd(s, a) = m.cmd_mm[k][a];
      d.v_cmd(s, a) = rates.v[k][a];
      d.a_cmd(s, a) = rates.a[k][a];
      d.x_meas(s, a) = m.pos_mm[k][a];
      d.v_meas(s, a) = m.vel_mm_s[k][a];
      d.a_meas(s, a) =
          (boxcar_at(m.raw.head_mps2, ks, a, q) - boxcar_at(m.raw.table_mps2, ks, a, q)) * 1000.0;  // mm/s²
    }
    d.t_s[s] = static_cast<double>(m.sample_index[k] - m.sample_index.front()) / m.fs_hz;
  }
}

// Per decimated sample: each sensor's case temperature change since the start, and the
// stretch between M102 marks it lies in.
void temperatures_and_segments(const Run& run, RunResiduals& d) {
  const Measurement& m = d.measurement;
  const Eigen::Index n = d.n;
  d.temp_c.resize(n, 2);
  d.segment.assign(static_cast<std::size_t>(n), 0);
  std::vector<std::int64_t> marks;
  for (const auto& t : m.triggers)
    if (t.code == trigger::segment_mark) marks.push_back(t.sample_index);
  const std::int64_t first_frame = run.frames.front().sample_index;
  float t0[2] = {kNaN, kNaN};
  for (Eigen::Index s = 0; s < n; ++s) {
    const std::size_t k = d.trace[static_cast<std::size_t>(s)];
    const auto fi = static_cast<std::size_t>(
        std::clamp<std::int64_t>(m.sample_index[k] - first_frame, 0, static_cast<std::int64_t>(run.frames.size()) - 1));
    for (int sn = 0; sn < 2; ++sn) {
      if (std::isnan(t0[sn])) t0[sn] = run.frames[fi].temp_c[sn];
      d.temp_c(s, sn) =
          std::isfinite(run.frames[fi].temp_c[sn]) ? static_cast<double>(run.frames[fi].temp_c[sn] - t0[sn]) : 0.0;
    }
    d.segment[static_cast<std::size_t>(s)] =
        static_cast<int>(std::upper_bound(marks.begin(), marks.end(), m.sample_index[k]) - marks.begin());
  }
}

// Which axes move, which sensor moves each, and what each has as reference available.
void axes_and_references(const Run& run, RunResiduals& d) {
  const Measurement& m = d.measurement;
  for (int a = 0; a < 3; ++a) {
    const double lo = d.cmd.col(a).minCoeff(), hi = d.cmd.col(a).maxCoeff();
    d.owner[a] = axis_owner(run.meta.machine, a);
    d.moving[a] = hi - lo > 0.5 && d.owner[a] >= 0;
    bool finite = run.channels.ref[a];
    for (Eigen::Index s = 0; s < d.n && finite; ++s)
      finite = std::isfinite(m.ref_mm[d.trace[static_cast<std::size_t>(s)]][a]);
    d.has_ref[a] = finite;
  }
  for (const auto& p : run.meta.psd) {
    const int a = axis_index(p.measures);
    if (a >= 0) d.has_psd[a] = true;
  }
  d.reference = (d.has_ref[0] || d.has_ref[1] || d.has_ref[2]) ? "ref" : (d.has_psd[0] || d.has_psd[1]) ? "psd" : "cmd";
}

void hold_out(RunResiduals& d) {
  d.heldout.resize(static_cast<std::size_t>(d.n));
  for (Eigen::Index s = 0; s < d.n; ++s)
    d.heldout[static_cast<std::size_t>(s)] = static_cast<int>(d.t_s[s] / kHeldOutBlockS) % 2 == 1;
}

// The integrated motion as it was integrated (sensor time, moved onto the set-point's
// time), the standstills the pipeline found, the moves' starts; per decimated sample.
struct IntegratedMotion {
  std::vector<Eigen::Vector3d> x_mm, v_mm_s;
  std::vector<std::uint8_t> zupt, bias_step;
};

IntegratedMotion integrated_motion(const RunResiduals& d) {
  namespace sf = fusion::schedule_flag;
  const Measurement& m = d.measurement;
  const auto& sched = m.raw.schedule;
  const auto ns = static_cast<double>(sched.flags.size());
  const auto n = static_cast<std::size_t>(d.n);
  IntegratedMotion ins{std::vector<Eigen::Vector3d>(n), std::vector<Eigen::Vector3d>(n),
                       std::vector<std::uint8_t>(n, 0), std::vector<std::uint8_t>(n, 0)};
  std::size_t prev_k = 0;
  for (std::size_t s = 0; s < n; ++s) {
    const double ks = static_cast<double>(d.trace[s]) + d.delay_samples;
    for (int a = 0; a < 3; ++a)
      ins.x_mm[s][a] = interpolate_at(m.raw.pos_mm, ks, a), ins.v_mm_s[s][a] = interpolate_at(m.raw.vel_mm_s, ks, a);
    const auto k = static_cast<std::size_t>(std::clamp(std::round(ks), 0.0, ns - 1.0));
    ins.zupt[s] = (sched.flags[k] & sf::rest) && k < sched.zupt_sigma_um_s.size() && sched.zupt_sigma_um_s[k] == 0.0F;
    for (std::size_t j = s == 0 ? k : prev_k + 1; j <= k && j < sched.flags.size(); ++j)
      if (sched.flags[j] & sf::move_start) ins.bias_step[s] = 1;
    prev_k = k;
  }
  return ins;
}

// PSD readings per axis (every 10th of each strip).
std::array<std::vector<const fusion::PositionFix*>, 3> psd_fixes_per_axis(const Run& run,
                                                                          const fusion::SupportSchedule& sched) {
  std::array<std::vector<const fusion::PositionFix*>, 3> fixes;
  std::vector<int> count(run.meta.psd.size() + 1, 0);
  for (const auto& fx : sched.fixes) {
    if (fx.strip < 0 || static_cast<std::size_t>(fx.strip) >= run.meta.psd.size()) continue;
    if (count[static_cast<std::size_t>(fx.strip)]++ % 10 != 0) continue;
    fixes[static_cast<std::size_t>(fx.axis)].push_back(&fx);
  }
  return fixes;
}

// An axis' track before its observations: steps, the moves' starts, the standstills and
// the integrated velocity.
void start_track(const RunResiduals& d, const IntegratedMotion& ins, int a, AxisTrack& t) {
  const Measurement& m = d.measurement;
  const Eigen::Index n = d.n;
  t.present = true;
  t.h_s = Eigen::VectorXd::Constant(n, d.dt_s);
  for (Eigen::Index s = 1; s < n; ++s)
    t.h_s[s] = static_cast<double>(m.sample_index[d.trace[static_cast<std::size_t>(s)]] -
                                   m.sample_index[d.trace[static_cast<std::size_t>(s - 1)]]) /
               m.fs_hz;
  t.bias_step = ins.bias_step, t.zupt = ins.zupt;
  t.start_bias_sigma_um_s2 = m.supports.start_bias_sigma_um_s2[a];
  t.v_um_s.resize(n);
  for (Eigen::Index s = 0; s < n; ++s) t.v_um_s[s] = ins.v_mm_s[static_cast<std::size_t>(s)][a] * 1000.0;
}

// An axis with the instrument's column: every sample observed against it.
void reference_rows(const RunResiduals& d, const IntegratedMotion& ins, int a, AxisTrack& t, ChannelRows& machine,
                    ChannelRows& pipeline) {
  const Measurement& m = d.measurement;
  for (Eigen::Index s = 0; s < d.n; ++s) {
    const std::size_t k = d.trace[static_cast<std::size_t>(s)];
    const double ref = m.ref_mm[k][a];
    t.obs.push_back({static_cast<int>(s), (ins.x_mm[static_cast<std::size_t>(s)][a] - ref) * 1000.0, 0.1,
                     d.heldout[static_cast<std::size_t>(s)], -1});
    machine.add(static_cast<int>(s), a, (ref - m.cmd_mm[k][a]) * 1000.0, 0.2);
    pipeline.add(static_cast<int>(s), a, (m.pos_mm[k][a] - ref) * 1000.0, 1.0);
  }
}

// An axis with PSD strips: observed where a strip is lit (on the set-point's time), each
// strip with an offset of its own (its mounting).
void psd_rows(const RunResiduals& d, const std::vector<const fusion::PositionFix*>& fixes, std::size_t strips,
              std::size_t step, int a, AxisTrack& t, ChannelRows& machine, ChannelRows& pipeline) {
  const Measurement& m = d.measurement;
  std::vector<int> tag_of(strips, -1);
  for (const auto* fx : fixes) {
    const double pos = static_cast<double>(fx->k) - d.delay_samples;  // on the set-point's time
    const auto s = static_cast<int>(std::lround(pos / static_cast<double>(step)));
    if (s < 0 || s >= d.n) continue;
    auto& tag = tag_of[static_cast<std::size_t>(fx->strip)];
    if (tag < 0) tag = t.tags++;
    t.obs.push_back({s, m.raw.pos_mm[fx->k][a] * 1000.0 - fx->position_um, std::hypot(fx->sigma_um, 0.05),
                     d.heldout[static_cast<std::size_t>(s)], tag});
    const double c = interpolate_at(m.cmd_mm, pos, a) * 1000.0;
    machine.add(s, a, fx->position_um - c, std::hypot(fx->sigma_um, 0.2));
    pipeline.add(s, a, interpolate_at(m.pos_mm, pos, a) * 1000.0 - fx->position_um, 1.0);
  }
  std::stable_sort(t.obs.begin(), t.obs.end(), [](const auto& x, const auto& y) { return x.sample < y.sample; });
}

// An axis with only its set-point: every sample observed against that.
void set_point_rows(const RunResiduals& d, const IntegratedMotion& ins, int a, AxisTrack& t, ChannelRows& pipeline) {
  const Measurement& m = d.measurement;
  for (Eigen::Index s = 0; s < d.n; ++s) {
    const std::size_t k = d.trace[static_cast<std::size_t>(s)];
    t.obs.push_back({static_cast<int>(s), (ins.x_mm[static_cast<std::size_t>(s)][a] - m.cmd_mm[k][a]) * 1000.0, 0.5,
                     d.heldout[static_cast<std::size_t>(s)], -1});
    pipeline.add(static_cast<int>(s), a, (m.pos_mm[k][a] - m.cmd_mm[k][a]) * 1000.0, 1.0);
  }
}

// Per axis its track against the best reference it has, and the rows of the machine and
// pipeline channels.
void build_tracks(const Run& run, std::size_t step, const IntegratedMotion& ins, RunResiduals& d) {
  const auto fixes = psd_fixes_per_axis(run, d.measurement.raw.schedule);
  d.machine.name = "machine", d.pipeline.name = "pipeline";
  ChannelRows machine{d.machine, {}, {}}, pipeline{d.pipeline, {}, {}};
  for (int a = 0; a < 3; ++a) {
    AxisTrack& t = d.tracks[static_cast<std::size_t>(a)];
    std::string& reference = d.axis_reference[static_cast<std::size_t>(a)];
    start_track(d, ins, a, t);
    if (d.has_ref[a]) {
      reference = "ref";
      reference_rows(d, ins, a, t, machine, pipeline);
    } else if (!fixes[static_cast<std::size_t>(a)].empty()) {
      reference = "psd";
      psd_rows(d, fixes[static_cast<std::size_t>(a)], run.meta.psd.size(), step, a, t, machine, pipeline);
    } else {
      reference = "cmd";
      set_point_rows(d, ins, a, t, pipeline);
    }
  }
  machine.finish();
  pipeline.finish();
}

}  // namespace

RunResiduals build_residuals(const Run& run) {
  if (run.frames.empty()) throw InputError("explain: run '" + run.meta.id + "' holds no frames");
  RunResiduals d;
  d.run_id = run.meta.id;
  d.meta = run.meta;
  d.measurement = nominal_measurement(run);
  const Measurement& m = d.measurement;
  if (m.sample_index.size() < 100 || m.raw.empty())
    throw InputError("explain: run '" + run.meta.id + "' has no motion to explain");
  d.fs_hz = m.fs_hz;
  d.delay_samples = run.meta.acquisition.daq_group_delay_samples;
  const std::size_t step = decimate(d);
  decimated_kinematics(set_point_rates(m, step), step, d);
  temperatures_and_segments(run, d);
  axes_and_references(run, d);
  hold_out(d);
  build_tracks(run, step, integrated_motion(d), d);
  return d;
}

}  // namespace eical::dsp::model
