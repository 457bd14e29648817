#include "dsp/model/spectral_tests.hpp"

#include "dsp/core/chi2.hpp"
#include "dsp/core/median.hpp"

#include <unsupported/Eigen/FFT>

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdio>
#include <numbers>

namespace eical::dsp::model {
namespace {

constexpr std::size_t kSeg = 2048;  // 0.2 s at 10 kHz: 5 Hz bins
constexpr double kMinHz = 3.0;
constexpr double kMotionMinHz = 25.0;  // a program's own acceleration is far below

struct Spectra {
  // Per axis: summed |X|² of table, head, head − table, and the table·head* cross term.
  std::vector<double> pt[3], ph[3], pr[3];
  std::vector<std::complex<double>> cth[3];
  int segments = 0;
};

// χ²(2K)/2K exceeded with probability ~3e-7 (z = 5).
double threshold(int k) { return chi2_quantile(2.0 * k, 5.0) / (2.0 * k); }

}  // namespace

VibrationTests vibration_tests(const RunResiduals& r) {
  VibrationTests out;
  const auto& raw = r.measurement.raw;
  const auto& flags = raw.schedule.flags;
  const std::size_t n = std::min(flags.size(), raw.head_mps2.size());
  const double fs = r.fs_hz;
  const std::size_t nb = kSeg / 2 + 1;
  Spectra sp;
  for (int a = 0; a < 3; ++a)
    sp.pt[a].assign(nb, 0.0), sp.ph[a].assign(nb, 0.0), sp.pr[a].assign(nb, 0.0), sp.cth[a].assign(nb, 0.0);
  std::vector<double> win(kSeg);
  double w2 = 0.0;
  for (std::size_t i = 0; i < kSeg; ++i)
    win[i] = 0.5 - 0.5 * std::cos(2.0 * std::numbers::pi * static_cast<double>(i) / kSeg), w2 += win[i] * win[i];
  Eigen::FFT<double> fft;
  std::vector<double> bt(kSeg), bh(kSeg), br(kSeg);
  std::vector<std::complex<double>> ft, fh, fr;
  auto add_segment = [&](Spectra& to, std::size_t s0) {
    for (int a = 0; a < 3; ++a) {
      double mt = 0.0, mh = 0.0;
      for (std::size_t i = 0; i < kSeg; ++i) mt += raw.table_mps2[s0 + i][a], mh += raw.head_mps2[s0 + i][a];
      mt /= kSeg, mh /= kSeg;
      for (std::size_t i = 0; i < kSeg; ++i) {
        bt[i] = (raw.table_mps2[s0 + i][a] - mt) * win[i];
        bh[i] = (raw.head_mps2[s0 + i][a] - mh) * win[i];
        br[i] = bh[i] - bt[i];
      }
      fft.fwd(ft, bt), fft.fwd(fh, bh), fft.fwd(fr, br);
      for (std::size_t f = 0; f < nb; ++f) {
        to.pt[a][f] += std::norm(ft[f]), to.ph[a][f] += std::norm(fh[f]), to.pr[a][f] += std::norm(fr[f]);
        to.cth[a][f] += ft[f] * std::conj(fh[f]);
      }
    }
    ++to.segments;
  };
  // Segments wholly inside standstills, half overlapping, from 0.25 s after each began:
  // a position loop taking up its lag (1/kv ≈ 30 ms) is motion, not vibration. Quiet or
  // not — a standstill the detector found ringing is where vibration is. Segments of the
  // motion (0.25 s clear of its start and end) serve the common test above kMotionMinHz,
  // where a program with few standstills (a circle) has its vibration.
  Spectra moving;
  for (int a = 0; a < 3; ++a)
    moving.pt[a].assign(nb, 0.0), moving.ph[a].assign(nb, 0.0), moving.pr[a].assign(nb, 0.0),
        moving.cth[a].assign(nb, 0.0);
  auto still = [&](std::size_t k) { return (flags[k] & fusion::schedule_flag::rest) != 0; };
  const auto settle = static_cast<std::size_t>(0.25 * fs);
  for (std::size_t k = 0; k < n;) {
    const bool rest = still(k);
    std::size_t e = k;
    while (e + 1 < n && still(e + 1) == rest) ++e;
    if (rest) {
      for (std::size_t s0 = k + settle; s0 + kSeg <= e + 1; s0 += kSeg / 2) add_segment(sp, s0);
    } else {
      for (std::size_t s0 = k + settle; s0 + kSeg + settle <= e + 1; s0 += kSeg / 2) add_segment(moving, s0);
    }
    k = e + 1;
  }
  out.seconds_used = static_cast<double>(sp.segments) * kSeg / 2.0 / fs;
  const double df = fs / kSeg, g = r.meta.site.g_mps2;
  auto floor_of = [&](int s) {
    const double n_g = r.meta.sensors[s].noise_ug_per_rthz * 1e-6 * g;
    return 2.0 * n_g * n_g;
  };
  out.floor_ug_per_rthz = std::hypot(r.meta.sensors[0].noise_ug_per_rthz, r.meta.sensors[1].noise_ug_per_rthz);
  double worst_common = 0.0, worst_diff = 0.0, disp_diff = 0.0, coh_sum = 0.0, coh_w = 0.0, thr = 0.0;
  std::vector<SpectralLine> common_lines, diff_lines;
  // One set of spectra against its floor: the common test, and the differential one if asked.
  auto analyse = [&](const Spectra& S, double lo_hz, bool differential) {
    const double scale = 2.0 / (fs * w2 * S.segments);  // one-sided PSD, (m/s²)²/Hz
    thr = std::max(3.0, threshold(S.segments));
    const std::size_t f_lo = static_cast<std::size_t>(std::ceil(lo_hz / df)),
                      f_hi = static_cast<std::size_t>(0.45 * fs / df);
    for (int a = 0; a < 3; ++a) {
      // The floor each signal really has: the data sheet times the median over the band (the
      // DAQ's own noise, a sensor better or worse than its sheet), never below the sheet's half.
      std::vector<double> rt, rh, rr;
      for (std::size_t f = f_lo; f < f_hi; ++f) {
        rt.push_back(S.pt[a][f] * scale / floor_of(0));
        rh.push_back(S.ph[a][f] * scale / floor_of(1));
        rr.push_back(S.pr[a][f] * scale / (floor_of(0) + floor_of(1)));
      }
      const double ft0 = floor_of(0) * std::max(0.5, dsp::median(rt, 1.0)),
                   fh0 = floor_of(1) * std::max(0.5, dsp::median(rh, 1.0));
      const double fr0 = (floor_of(0) + floor_of(1)) * std::max(0.5, dsp::median(rr, 1.0));
      double ex_common = 0.0, ex_diff = 0.0, disp = 0.0;
      for (std::size_t f = f_lo; f < f_hi; ++f) {
        const double pt = S.pt[a][f] * scale, ph = S.ph[a][f] * scale, pr = S.pr[a][f] * scale;
        const double w = 2.0 * std::numbers::pi * static_cast<double>(f) * df;
        if (pr > thr * fr0 &&
            f >= 2) {  // relative motion at this frequency (above the lowest bin: the last of a settling)
          if (!differential) continue;
          ex_diff += (pr - fr0) * df;
          disp += (pr - fr0) * df / (w * w * w * w);
          diff_lines.push_back({static_cast<double>(f) * df, pr / fr0, std::sqrt(2.0 * (pr - fr0) * df) / (g * 1e-3)});
        } else if (pt > thr * ft0 && ph > thr * fh0) {
          const double coh = std::norm(S.cth[a][f]) / std::max(1e-300, S.pt[a][f] * S.ph[a][f]);
          if (coh > 0.7 && pr < 0.1 * std::min(pt, ph)) {  // in both, in phase, cancelling in head − table
            ex_common += 0.5 * ((pt - ft0) + (ph - fh0)) * df;
            coh_sum += coh * pt, coh_w += pt;
            common_lines.push_back({static_cast<double>(f) * df, std::min(pt / ft0, ph / fh0),
                                    std::sqrt(2.0 * (pt - ft0) * df) / (g * 1e-3)});
          }
        }
      }
      worst_common = std::max(worst_common, std::sqrt(ex_common) / (g * 1e-3));
      worst_diff = std::max(worst_diff, std::sqrt(ex_diff) / (g * 1e-3));
      disp_diff = std::max(disp_diff, std::sqrt(disp) * 1e6);
    }
  };
  const bool rest_ok = sp.segments >= 2, moving_ok = moving.segments >= 4;
  std::string where;
  if (rest_ok) analyse(sp, kMinHz, true);
  if (sp.segments < 4 && moving_ok && common_lines.empty()) {
    analyse(moving, kMotionMinHz, false);
    where = " (during the motion, above " + std::to_string(static_cast<int>(kMotionMinHz)) + " Hz)";
  }
  if (!rest_ok && !moving_ok) {
    out.common.evidence = out.differential.evidence =
        "too little standstill or steady motion for a spectrum (" + std::to_string(sp.segments) + " segments of 0.2 s)";
    return out;
  }
  if (!rest_ok)
    out.differential.evidence =
        "too little standstill for a spectrum of head - table (" + std::to_string(sp.segments) + " segments of 0.2 s)";
  auto top = [](std::vector<SpectralLine>& v) {
    std::sort(v.begin(), v.end(), [](const auto& x, const auto& y) { return x.amp_mg > y.amp_mg; });
    if (v.size() > 5) v.resize(5);
  };
  const std::size_t n_common = common_lines.size(), n_diff = diff_lines.size();
  top(common_lines), top(diff_lines);
  char buf[256];
  out.common.rms_mg = worst_common;
  out.common.coherence = coh_w > 0.0 ? coh_sum / coh_w : 0.0;
  out.common.lines = common_lines;
  out.common.found = !common_lines.empty();
  std::snprintf(
      buf, sizeof buf,
      "%zu bins above %.1fx the noise floor in both sensors, coherent (%.2f), cancelling in head - table; %.3f mg RMS",
      n_common, thr, out.common.coherence, worst_common);
  out.common.evidence = buf + where;
  out.differential.rms_mg = worst_diff;
  out.differential.displacement_um = disp_diff;
  out.differential.lines = diff_lines;
  out.differential.found = !diff_lines.empty();
  std::snprintf(buf, sizeof buf,
                "%zu bins of head - table above %.1fx its noise floor; %.3f mg RMS, %.3f um RMS displacement", n_diff,
                thr, worst_diff, disp_diff);
  if (rest_ok) out.differential.evidence = buf;
  return out;
}

}  // namespace eical::dsp::model
