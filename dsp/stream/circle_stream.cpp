#include "dsp/stream/circle_stream.hpp"

#include "dsp/core/error.hpp"
#include "dsp/eval/circle_diagnostics.hpp"

#include <algorithm>
#include <cmath>

namespace eical::dsp {
namespace {

// The diagnostics' passes as the stream spilled them, one spill per direction.
class SpilledPasses final : public eval::PassReplay {
 public:
  void add(int direction, double fs_hz, std::size_t samples, Spill& spill) {
    info_.push_back({direction, fs_hz, samples});
    spills_.push_back(&spill);
  }
  [[nodiscard]] const std::vector<Pass>& passes() const override { return info_; }
  void replay(const std::function<void(std::size_t, const Eigen::Vector2d&, const Eigen::Vector2d&)>& f) override {
    for (std::size_t k = 0; k < spills_.size(); ++k)
      for_each_record<Doubles<4>>(*spills_[k], [&](const Doubles<4>& r) {
        f(k, Eigen::Vector2d(r.v[0], r.v[1]), Eigen::Vector2d(r.v[2], r.v[3]));
      });
  }

 private:
  std::vector<Pass> info_;
  std::vector<Spill*> spills_;
};

}  // namespace

CircleStream::CircleStream(const Run& run, std::vector<eval::CircleSegment> segments,
                           std::optional<std::string> segment_error, bool reference, const SpillFactory& spills)
    : run_(run), segment_error_(std::move(segment_error)), reference_(reference) {
  const Program& p = run.meta.program;
  std::tie(ia_, ib_) = plane_axes(p.plane);
  if (segment_error_) return;
  std::size_t n_dir[2] = {0, 0};
  for (const auto& s : segments) {
    const Range r{s.begin_index, s.end_index, s.direction == "ccw" ? 0 : 1, s.samples};
    ranges_.push_back(r);
    by_dir_[r.dir].push_back(r);
    n_dir[r.dir] += s.samples;
  }
  if (ranges_.empty()) {
    segment_error_ = "no stretch between two M102 marks sweeps the programmed " + std::to_string(p.arc_deg) +
                     " deg about the programmed centre";
    return;
  }
  // The trace keeps the points the result's plot shows (every n/3600-th of the combined
  // trace, counter-clockwise first): a plot of a long run needs no more.
  const std::size_t stride = std::max<std::size_t>(1, (n_dir[0] + n_dir[1]) / 3600);
  const bool arc = p.arc_deg < 360.0;
  for (int d = 0; d < 2; ++d) {
    if (by_dir_[d].empty()) continue;
    eval::CircleAccumulator::Options o;
    o.center_mm = {p.center_mm[0], p.center_mm[1]};
    o.radius_mm = p.radius_mm;
    o.direction = d == 0 ? "ccw" : "cw";
    o.arc_deg = p.arc_deg;
    o.trace_stride = stride;
    o.trace_offset = d == 1 ? n_dir[0] : 0;
    meas_.acc[d].emplace(o);
    if (reference_) ref_.acc[d].emplace(o);
    if (!(p.radius_mm > 0.0)) {  // what evaluate_circle()/evaluate_arc() refuse first
      const std::string e = std::string(arc ? "arc" : "circle") + " evaluation: nominal radius must be positive";
      meas_.error = ref_.error = e;
    }
    if (!arc) {
      pass_spill_[d] = spills();
      pass_writer_[d] = std::make_unique<SpillWriter<Doubles<4>>>(*pass_spill_[d]);
    }
  }
}

void CircleStream::enter(const Range& r) {
  for (Channel* c : {&meas_, &ref_})
    if (c->acc[r.dir] && !c->error) c->acc[r.dir]->begin(r.samples);
}

void CircleStream::leave(const Range& r) {
  for (Channel* c : {&meas_, &ref_}) {
    if (!c->acc[r.dir] || c->error) continue;
    try {
      c->acc[r.dir]->end();
    } catch (const InputError& e) {
      c->error = e.what();
    }
  }
  // (measured − reference) radius deviation, point by point (both channels hold the same samples).
  if (meas_.acc[r.dir] && ref_.acc[r.dir] && !meas_.error && !ref_.error) {
    const auto& dm = meas_.acc[r.dir]->revolution_deviations();
    const auto& dr = ref_.acc[r.dir]->revolution_deviations();
    for (std::size_t i = 0; i < dm.size() && i < dr.size(); ++i) accuracy_ss_ += (dm[i] - dr[i]) * (dm[i] - dr[i]);
    accuracy_n_ += std::min(dm.size(), dr.size());
  }
}

void CircleStream::sample(std::int64_t sample_index, const Eigen::Vector3d& pos_mm, const Eigen::Vector3d& cmd_mm,
                          const Eigen::Vector3d& ref_mm) {
  if (segment_error_) return;
  // Ranges that have ended (also one that no sample fell in: its too few samples are its error).
  while (next_ < ranges_.size() && sample_index >= ranges_[next_].second) {
    if (!inside_) enter(ranges_[next_]);
    leave(ranges_[next_]);
    inside_ = false;
    ++next_;
  }
  if (next_ < ranges_.size() && sample_index >= ranges_[next_].first) {
    const Range& r = ranges_[next_];
    if (!inside_) enter(r), inside_ = true;
    const Eigen::Vector2d pm(pos_mm[ia_], pos_mm[ib_]), pr(ref_mm[ia_], ref_mm[ib_]);
    for (auto [c, p] : {std::pair<Channel*, const Eigen::Vector2d*>{&meas_, &pm}, {&ref_, &pr}}) {
      if (!c->acc[r.dir] || c->error) continue;
      try {
        c->acc[r.dir]->add(sample_index, *p);
      } catch (const InputError& e) {
        c->error = e.what();
      }
    }
  }
  for (int d = 0; d < 2; ++d)
    if (pass_writer_[d] && sample_index >= by_dir_[d].front().first && sample_index < by_dir_[d].back().second) {
      pass_writer_[d]->put({{cmd_mm[ia_], cmd_mm[ib_], pos_mm[ia_], pos_mm[ib_]}});
      ++pass_samples_[d];
    }
}

void CircleStream::finish(Analysis& a) {
  for (; next_ < ranges_.size(); ++next_) {  // the trace ended (a range not closed has no samples after it)
    if (!inside_) enter(ranges_[next_]);
    leave(ranges_[next_]);
    inside_ = false;
  }
  const Program& p = run_.meta.program;
  if (segment_error_) {
    a.flags.push_back({FlagCode::evaluation_failed, "circle", *segment_error_});
    a.degraded = true;
    return;
  }
  // The first failure in the order evaluate_channel() meets them (counter-clockwise first).
  auto combined = [&](Channel& c) -> std::optional<eval::CircleResult> {
    if (c.error) throw InputError(*c.error);
    std::optional<eval::CircleResult> out;
    for (int d = 0; d < 2; ++d) {
      if (!c.acc[d]) continue;
      const eval::CircleResult r = c.acc[d]->result();
      out = out ? eval::combine(*out, r) : r;
    }
    return out;
  };
  try {
    a.circle = combined(meas_);
  } catch (const InputError& e) {
    a.flags.push_back({FlagCode::evaluation_failed, "circle", e.what()});
    a.degraded = true;
    return;
  }
  if (p.direction == "both" && (by_dir_[0].empty() || by_dir_[1].empty()))
    a.flags.push_back({FlagCode::one_direction, "circle",
                       std::string("the program runs both directions but only ") + (by_dir_[0].empty() ? "cw" : "ccw") +
                           " was found"});
  if (!a.circle->circular_hysteresis_H_um)
    a.flags.push_back({FlagCode::figure_null, "circle.circular_hysteresis_H_um",
                       "ISO 230-4 H needs both directions (this run has " + a.circle->direction + " only)"});

  // The reference instrument (or the simulator's truth) through the same evaluation.
  if (reference_) {
    try {
      a.circle_reference = combined(ref_);
      if (a.circle->points == a.circle_reference->points && a.circle->points > 0 && accuracy_n_ == a.circle->points)
        a.circle_accuracy_rms_um = std::sqrt(accuracy_ss_ / static_cast<double>(accuracy_n_));
    } catch (const InputError& e) {
      a.flags.push_back({FlagCode::circle_reference, "circle", e.what()});
    }
  }

  // Diagnostics: one pass per direction over its steady revolutions.
  if (p.arc_deg < 360.0) {
    a.flags.push_back({FlagCode::figure_null, "diagnostics",
                       "the ballbar-class diagnostics need full revolutions (this run is a " +
                           std::to_string(static_cast<int>(std::lround(p.arc_deg))) + " deg partial arc)"});
    return;
  }
  SpilledPasses passes;
  for (int d = 0; d < 2; ++d) {
    if (!pass_writer_[d]) continue;
    pass_writer_[d]->flush();
    passes.add(d == 0 ? +1 : -1, a.measurement.fs_hz, pass_samples_[d], *pass_spill_[d]);
  }
  eval::DiagnosticsOptions opt;
  opt.centre_mm = {p.center_mm[0], p.center_mm[1]};
  opt.radius_mm = p.radius_mm;
  opt.feed_mm_min = p.feed_mm_min;
  try {
    a.diagnostics = eval::diagnose_circle(passes, opt);
    for (auto& reason : eval::null_reasons(*a.diagnostics, opt)) a.flags.push_back(std::move(reason));
  } catch (const InputError& e) {
    a.flags.push_back({FlagCode::figure_null, "diagnostics", e.what()});
  }
}

}  // namespace eical::dsp
