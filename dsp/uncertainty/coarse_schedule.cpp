#include "dsp/uncertainty/coarse_schedule.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <tuple>

namespace eical::dsp::uncertainty {

namespace {

// The pipeline's model on the coarse grid: σ is carried per coarse sample (zupt) and per
// fix, so the model's floors are folded in; no gate, no reset.
fusion::ErrorModel coarse_model(const fusion::ErrorModel& model, std::size_t q) {
  fusion::ErrorModel m = model;
  m.zupt_sigma_um_s = 1e-9;
  m.psd_floor_um = 0.0;
  m.nbs_sigma_um_s = model.nbs_sigma_um_s / std::sqrt(static_cast<double>(q));
  m.gate_nis = 1e300;
  m.reset_after_rejections = 1 << 30;
  return m;
}

// ZUPT σ of fine sample k (0: its own; < 0: unused).
double zupt_sigma(const FineSchedule& in, std::size_t k) {
  const fusion::SupportSchedule& fine = *in.schedule;
  if (k < fine.zupt_sigma_um_s.size()) return static_cast<double>(fine.zupt_sigma_um_s[k]);
  if (in.zupt_unused && k < in.zupt_unused->size()) return (*in.zupt_unused)[k] ? -1.0 : 0.0;
  return 0.0;
}

// The flags and ZUPT σ of the block of fine samples [b, e): a move start if any; invalid
// if every sample is; a standstill if any sample rests, its σ that of the samples' combined
// information (−1: none used); else NBS on an axis held for at least half the block.
void coarsen_block(const FineSchedule& in, const fusion::ErrorModel& model, std::size_t b, std::size_t e,
                   std::uint8_t& flags_out, float& zupt_sigma_out) {
  namespace sf = fusion::schedule_flag;
  std::uint8_t any = 0;
  std::size_t invalid = 0, rest_used = 0, nbs[3] = {0, 0, 0};
  double info = 0.0;  // Σ 1/σ² of the block's standstill velocities
  bool rest = false;
  for (std::size_t k = b; k < e; ++k) {
    const auto f = static_cast<std::uint8_t>(in.schedule->flags[k] & in.flag_mask);
    any |= f;
    if (f & sf::invalid) {
      ++invalid;
      continue;
    }
    if (f & sf::rest) {
      rest = true;
      const double z = zupt_sigma(in, k);
      if (z >= 0.0) {
        const double sg = std::max(model.zupt_sigma_um_s, z);
        info += 1.0 / (sg * sg), ++rest_used;
      }
    } else {
      for (int a = 0; a < 3; ++a)
        if (f & fusion::nbs_flag(a)) ++nbs[a];
    }
  }
  std::uint8_t flags = static_cast<std::uint8_t>(any & sf::move_start);
  if (invalid == e - b) flags |= sf::invalid;
  if (rest) {
    flags |= sf::rest;
    zupt_sigma_out = rest_used > 0 ? static_cast<float>(1.0 / std::sqrt(info)) : -1.0F;
  } else {
    zupt_sigma_out = 0.0F;
    for (int a = 0; a < 3; ++a)
      if (2 * nbs[a] >= e - b) flags |= fusion::nbs_flag(a);
  }
  flags_out = flags;
}

// Fixes: one per (coarse sample, strip), inverse-variance combined, into c's schedule and
// fix_noise_um. The way and the velocity (the scale's and the timing's rows) are read where
// the coarse sample's state is, its block's last fine sample, not at the readings' mean: a
// strip crossed at speed would otherwise read them v·block/2 from where the error is
// compared. Without the way in the schedule neither state exists and the rows ignore both.
void combine_fixes(const std::vector<fusion::PositionFix>& fixes, const fusion::ErrorModel& model, std::size_t n,
                   std::size_t q, const std::vector<Eigen::Vector3d>& vel_at_end, CoarseSchedule& c) {
  // (axis, Σ w, Σ w² σ_noise², Σ w·position) with w = 1/var as the pipeline weighs each fix.
  std::map<std::pair<std::size_t, int>, std::tuple<int, double, double, double>> comb;
  for (const auto& f : fixes) {
    if (f.k >= n) continue;
    const double noise = f.sigma_um * f.sigma_um + model.psd_floor_um * model.psd_floor_um;
    const double var = noise + f.model_sigma_um * f.model_sigma_um;
    if (!(var > 0.0) || !std::isfinite(var)) continue;
    auto& [axis, w, wn, wp] = comb[{f.k / q, f.strip}];
    axis = f.axis;
    w += 1.0 / var, wn += noise / (var * var), wp += f.position_um / var;
  }
  for (const auto& [key, v] : comb) {
    fusion::PositionFix f;
    f.k = key.first, f.strip = key.second, f.axis = std::get<0>(v);
    f.sigma_um = 1.0 / std::sqrt(std::get<1>(v));
    f.position_um = std::get<3>(v) / std::get<1>(v);  // where on its strip (the nonlinearity's response)
    if (f.k < c.schedule.way_mm.size()) f.way_mm = static_cast<double>(c.schedule.way_mm[f.k][f.axis]);
    if (f.k < vel_at_end.size()) f.vel_mm_s = vel_at_end[f.k][f.axis];
    c.schedule.fixes.push_back(f);
    c.fix_noise_um.push_back(std::sqrt(std::get<2>(v)) / std::get<1>(v));  // σ of the weighted mean's noise
  }
}

// The velocity (mm/s) at each block's last sample from the way ±4 samples around it, over
// their true spacing (lost frames), where the schedule carries the way.
std::vector<Eigen::Vector3d> way_velocity_at_block_ends(const FineSchedule& in, std::size_t n, std::size_t q) {
  const fusion::SupportSchedule& fine = *in.schedule;
  std::vector<Eigen::Vector3d> v;
  if (fine.way_mm.size() < n || !(in.fs_hz > 0.0) || n < 2) return v;
  const std::size_t nc = (n + q - 1) / q;
  v.resize(nc);
  for (std::size_t j = 0; j < nc; ++j) {
    const std::size_t k = std::min(n, j * q + q) - 1, lo = k >= 4 ? k - 4 : 0, hi = std::min(n - 1, k + 4);
    v[j] = fine.way_velocity_mm_s(lo, hi, in.index_at(hi) - in.index_at(lo), in.fs_hz);
  }
  return v;
}

}  // namespace

CoarseSchedule coarsen(const fusion::SupportSchedule& fine, const std::vector<std::int64_t>& sample_index,
                       const fusion::ErrorModel& model, std::size_t block, double fs_hz) {
  FineSchedule f;
  f.schedule = &fine;
  f.fs_hz = fs_hz;
  f.samples = std::min(fine.flags.size(), sample_index.size());
  f.index_at = [&sample_index](std::size_t k) { return sample_index[k]; };
  return coarsen(f, model, block);
}

CoarseSchedule coarsen(const FineSchedule& in, const fusion::ErrorModel& model, std::size_t q) {
  const fusion::SupportSchedule& fine = *in.schedule;
  CoarseSchedule c;
  q = std::max<std::size_t>(1, q);
  c.block = q;
  const std::size_t n = std::min(fine.flags.size(), in.samples);
  const std::size_t nc = (n + q - 1) / q;
  c.model = coarse_model(model, q);
  auto& s = c.schedule;
  s.zupt = fine.zupt;
  s.cupt = fine.cupt;
  s.flags.assign(nc, 0);
  s.zupt_sigma_um_s.assign(nc, -1.0F);
  c.sample_index.resize(nc);
  c.fine_end.resize(nc);
  for (std::size_t j = 0; j < nc; ++j) {
    const std::size_t b = j * q, e = std::min(n, b + q);
    c.fine_end[j] = e - 1;
    c.sample_index[j] = in.index_at(e - 1);
    coarsen_block(in, model, b, e, s.flags[j], s.zupt_sigma_um_s[j]);
    if (fine.way_mm.size() >= n) s.way_mm.push_back(fine.way_mm[e - 1]);
  }
  if (s.way_mm.size() != nc) s.way_mm.clear();
  combine_fixes(fine.fixes, model, n, q, way_velocity_at_block_ends(in, n, q), c);
  for (auto v : fine.velocity_means) {
    if (v.k >= n) continue;
    v.k /= q;
    v.sigma_um_s = std::max(v.sigma_um_s, model.zupt_sigma_um_s);  // the floor the pipeline applied
    s.velocity_means.push_back(v);
  }
  return c;
}

}  // namespace eical::dsp::uncertainty
