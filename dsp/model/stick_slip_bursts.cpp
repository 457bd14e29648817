#include "dsp/model/stick_slip_bursts.hpp"

#include "dsp/core/median.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

namespace eical::dsp::model {
namespace {

constexpr double kCreepMmS = 10.0;     // below this an axis creeps (600 mm/min)
constexpr double kStillMmS = 0.02;     // below this it stands
constexpr double kBurstSigma = 10.0;   // a burst: the high-passed acceleration beyond 10 σ
constexpr double kHalfWindowS = 1e-3;  // high-pass: minus the mean over ±1 ms
constexpr double kSawtoothHalfWindowS = 0.025;

// High-passed relative acceleration along axis a (a running mean over ±half samples
// removed), m/s².
std::vector<double> high_passed(const Measurement& m, int a, std::size_t n, std::ptrdiff_t half) {
  std::vector<double> hp(n, 0.0), pre(n + 1, 0.0);
  for (std::size_t k = 0; k < n; ++k) pre[k + 1] = pre[k] + (m.raw.head_mps2[k][a] - m.raw.table_mps2[k][a]);
  for (std::size_t k = 0; k < n; ++k) {
    const auto lo = static_cast<std::size_t>(std::max<std::ptrdiff_t>(0, static_cast<std::ptrdiff_t>(k) - half));
    const auto hi = std::min(n, k + static_cast<std::size_t>(half) + 1);
    hp[k] = (m.raw.head_mps2[k][a] - m.raw.table_mps2[k][a]) - (pre[hi] - pre[lo]) / static_cast<double>(hi - lo);
  }
  return hp;
}

// The set-point speed of each raw sample (sensor time, `shift` samples behind the
// set-point's) as a zone: 0 standing, 1 creeping, 2 faster.
std::vector<std::uint8_t> speed_zones(const Measurement& m, int a, std::size_t n, std::ptrdiff_t shift) {
  const double fs = m.fs_hz;
  std::vector<std::uint8_t> zone(n, 0);
  for (std::size_t k = 1; k + 1 < n; ++k) {
    const std::ptrdiff_t c = static_cast<std::ptrdiff_t>(k) - shift;
    if (c < 1 || c + 1 >= static_cast<std::ptrdiff_t>(n)) continue;
    const double v =
        std::abs(m.cmd_mm[static_cast<std::size_t>(c + 1)][a] - m.cmd_mm[static_cast<std::size_t>(c - 1)][a]) * fs /
        2.0;
    zone[k] = v >= kCreepMmS ? 2 : v > kStillMmS ? 1 : 0;
  }
  return zone;
}

// Noise: the robust spread of the high-passed signal where the axis moves fast (what
// the drive and the sensors show without slipping); a run that only creeps has the
// creep itself for that — slips last milliseconds a few times a second, so the median
// of the creep's spread is its noise. 0 when neither has 200 samples.
double burst_noise(const std::vector<double>& hp, const std::vector<std::uint8_t>& zone) {
  std::vector<double> fast, creep;
  for (std::size_t k = 0; k < hp.size(); k += 3) {
    if (zone[k] == 2) fast.push_back(std::abs(hp[k]));
    if (zone[k] == 1) creep.push_back(std::abs(hp[k]));
  }
  const std::vector<double>& quiet = fast.size() >= 200 ? fast : creep;
  if (quiet.size() < 200) return 0.0;
  return 1.4826 * dsp::median(quiet, 0.0);
}

// One axis' bursts: in its creep zones (per zone) and elsewhere, and the time in each.
struct AxisBursts {
  int in_creep = 0, elsewhere = 0, zone_count = 0;
  double per_zone = 0.0;  // median over the creep zones
  double creep_s = 0.0, other_s = 0.0;
};

// Bursts: local peaks beyond kBurstSigma·sigma, at least `half` samples apart.
AxisBursts count_bursts(const std::vector<double>& hp, const std::vector<std::uint8_t>& zone, double sigma,
                        std::ptrdiff_t half, double fs) {
  AxisBursts b;
  std::vector<double> per_zone;
  int zone_bursts = 0;
  std::ptrdiff_t last_burst = -1000000;
  bool in_zone = false;
  for (std::size_t k = 0; k < hp.size(); ++k) {
    const bool creeping = zone[k] == 1;
    if (creeping && !in_zone) in_zone = true, zone_bursts = 0;
    if (!creeping && in_zone) {
      in_zone = false;
      per_zone.push_back(zone_bursts), ++b.zone_count;
    }
    (creeping ? b.creep_s : b.other_s) += zone[k] != 0 ? 1.0 / fs : 0.0;
    if (zone[k] == 0) continue;
    if (std::abs(hp[k]) > kBurstSigma * sigma && static_cast<std::ptrdiff_t>(k) - last_burst >= half) {
      last_burst = static_cast<std::ptrdiff_t>(k);
      if (creeping)
        ++b.in_creep, ++zone_bursts;
      else
        ++b.elsewhere;
    }
  }
  if (in_zone) per_zone.push_back(zone_bursts), ++b.zone_count;
  b.per_zone = dsp::median(per_zone, 0.0);
  return b;
}

// The moving axis with the most bursts per creep zone into `out` (axis −1: none could be
// measured).
void busiest_axis(const RunResiduals& r, std::size_t n, StickSlipFinding& out) {
  const Measurement& m = r.measurement;
  const auto shift =
      static_cast<std::ptrdiff_t>(std::lround(r.delay_samples));  // raw (sensor time) k ↔ set-point k − shift
  const auto half = static_cast<std::ptrdiff_t>(std::max(1.0, std::round(kHalfWindowS * m.fs_hz)));
  double best_per_zone = -1.0;
  for (int a = 0; a < 3; ++a) {
    if (!r.moving[a]) continue;
    const std::vector<double> hp = high_passed(m, a, n, half);
    const std::vector<std::uint8_t> zone = speed_zones(m, a, n, shift);
    const double sigma = burst_noise(hp, zone);
    if (!(sigma > 0.0)) continue;
    const AxisBursts b = count_bursts(hp, zone, sigma, half, m.fs_hz);
    if (b.per_zone > best_per_zone) {
      best_per_zone = b.per_zone;
      out.axis = a, out.creep_zones = b.zone_count, out.bursts_in_creep = b.in_creep,
      out.bursts_elsewhere = b.elsewhere, out.bursts_per_zone = b.per_zone;
      out.creep_seconds = b.creep_s, out.other_seconds = b.other_s;
    }
  }
}

// The slips' size where the reference shows them: the sawtooth's RMS × √12 in the creep
// zones, about the running mean over ±25 ms (a slower wander is no slip).
double sawtooth_um(const Measurement& m, int axis) {
  const double fs = m.fs_hz;
  const auto w = static_cast<std::ptrdiff_t>(std::max(2.0, std::round(kSawtoothHalfWindowS * fs)));
  const std::size_t nr = m.ref_mm.size();
  std::vector<double> e(nr, 0.0), pre(nr + 1, 0.0);
  for (std::size_t k = 0; k < nr; ++k) {
    e[k] = m.ref_mm[k][axis] - m.cmd_mm[k][axis];
    pre[k + 1] = pre[k] + (std::isfinite(e[k]) ? e[k] : 0.0);
  }
  double ss = 0.0;
  std::size_t cnt = 0;
  for (std::size_t k = static_cast<std::size_t>(w); k + static_cast<std::size_t>(w) + 1 < nr; ++k) {
    const double v = std::abs(m.cmd_mm[k + 1][axis] - m.cmd_mm[k - 1][axis]) * fs / 2.0;
    if (!(v > kStillMmS && v < kCreepMmS) || !std::isfinite(e[k])) continue;
    const double mean = (pre[k + static_cast<std::size_t>(w) + 1] - pre[k - static_cast<std::size_t>(w)]) /
                        static_cast<double>(2 * w + 1);
    ss += (e[k] - mean) * (e[k] - mean), ++cnt;
  }
  return cnt > 0 ? std::sqrt(ss / static_cast<double>(cnt)) * 1000.0 * std::sqrt(12.0) : 0.0;
}

std::string describe_stick_slip(const StickSlipFinding& out) {
  static const char* const kAx[3] = {"x", "y", "z"};
  char buf[400];
  std::snprintf(buf, sizeof buf,
                "%d bursts of relative acceleration beyond %.0f sigma while %s creeps (below %.0f mm/s; median %.0f "
                "per creep zone over %d zones, %.2f s) "
                "against %d over %.2f s of faster motion%s",
                out.bursts_in_creep, kBurstSigma, kAx[out.axis], kCreepMmS, out.bursts_per_zone, out.creep_zones,
                out.creep_seconds, out.bursts_elsewhere, out.other_seconds, "");
  std::string evidence = buf;
  if (out.slip_um > 0.0) {
    char b2[96];
    std::snprintf(b2, sizeof b2, "; the reference shows a %.2f um sawtooth there", out.slip_um);
    evidence += b2;
  }
  return evidence;
}

}  // namespace

StickSlipFinding stick_slip_test(const RunResiduals& run) {
  StickSlipFinding out;
  const Measurement& m = run.measurement;
  const std::size_t n = std::min({m.raw.head_mps2.size(), m.raw.table_mps2.size(), m.cmd_mm.size()});
  if (n < 1000) return out;
  busiest_axis(run, n, out);
  if (out.axis < 0) {
    out.evidence = "no moving axis with enough fast motion to measure the noise against";
    return out;
  }
  // A train per creep zone, in most zones: backlash taking up its play, a reversal spike's
  // step of acceleration, ring through the DAQ filter (its impulse response spans ~8 ms)
  // as a handful of peaks a millisecond apart, once per reversal.
  out.found = out.bursts_per_zone >= 8.0 && out.bursts_in_creep >= 20;
  if (run.has_ref[out.axis]) out.slip_um = sawtooth_um(m, out.axis);
  out.evidence = describe_stick_slip(out);
  return out;
}

Eigen::VectorXd creep_direction(const RunResiduals& run, int axis) {
  Eigen::VectorXd d = Eigen::VectorXd::Zero(run.v_cmd.rows());
  if (axis < 0 || axis > 2) return d;
  for (Eigen::Index k = 0; k < d.size(); ++k) {
    const double v = run.v_cmd(k, axis);
    if (std::abs(v) > kStillMmS && std::abs(v) < kCreepMmS) d[k] = v > 0.0 ? 1.0 : -1.0;
  }
  return d;
}

}  // namespace eical::dsp::model
