#include "dsp/model/vibration_spectra.hpp"

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

  Spectra() {
    const std::size_t nb = kSeg / 2 + 1;
    for (int a = 0; a < 3; ++a)
      pt[a].assign(nb, 0.0), ph[a].assign(nb, 0.0), pr[a].assign(nb, 0.0), cth[a].assign(nb, 0.0);
  }
};

// χ²(2K)/2K exceeded with probability ~3e-7 (z = 5).
double threshold(int k) { return chi2_quantile(2.0 * k, 5.0) / (2.0 * k); }

// One segment's transform: the Hann window and its power, the FFT and its buffers (reused
// from segment to segment).
struct SegmentTransform {
  std::vector<double> win = std::vector<double>(kSeg);
  double w2 = 0.0;
  Eigen::FFT<double> fft;
  std::vector<double> bt = std::vector<double>(kSeg), bh = std::vector<double>(kSeg), br = std::vector<double>(kSeg);
  std::vector<std::complex<double>> ft, fh, fr;

  SegmentTransform() {
    for (std::size_t i = 0; i < kSeg; ++i)
      win[i] = 0.5 - 0.5 * std::cos(2.0 * std::numbers::pi * static_cast<double>(i) / kSeg), w2 += win[i] * win[i];
  }
};

// The segment from s0, each axis' mean out and windowed, into the sums of `to`.
void add_segment(const RawTrace& raw, std::size_t s0, SegmentTransform& tr, Spectra& to) {
  const std::size_t nb = kSeg / 2 + 1;
  for (int a = 0; a < 3; ++a) {
    double mt = 0.0, mh = 0.0;
    for (std::size_t i = 0; i < kSeg; ++i) mt += raw.table_mps2[s0 + i][a], mh += raw.head_mps2[s0 + i][a];
    mt /= kSeg, mh /= kSeg;
    for (std::size_t i = 0; i < kSeg; ++i) {
      tr.bt[i] = (raw.table_mps2[s0 + i][a] - mt) * tr.win[i];
      tr.bh[i] = (raw.head_mps2[s0 + i][a] - mh) * tr.win[i];
      tr.br[i] = tr.bh[i] - tr.bt[i];
    }
    tr.fft.fwd(tr.ft, tr.bt), tr.fft.fwd(tr.fh, tr.bh), tr.fft.fwd(tr.fr, tr.br);
    for (std::size_t f = 0; f < nb; ++f) {
      to.pt[a][f] += std::norm(tr.ft[f]), to.ph[a][f] += std::norm(tr.fh[f]), to.pr[a][f] += std::norm(tr.fr[f]);
      to.cth[a][f] += tr.ft[f] * std::conj(tr.fh[f]);
    }
  }
  ++to.segments;
}

// Segments wholly inside standstills, half overlapping, from 0.25 s after each began:
// a position loop taking up its lag (1/kv ≈ 30 ms) is motion, not vibration. Quiet or
// not — a standstill the detector found ringing is where vibration is. Segments of the
// motion (0.25 s clear of its start and end) serve the common test above kMotionMinHz,
// where a program with few standstills (a circle) has its vibration.
void collect_segments(const RawTrace& raw, std::size_t n, double fs, SegmentTransform& tr, Spectra& rest,
                      Spectra& moving) {
  const auto& flags = raw.schedule.flags;
  auto still = [&](std::size_t k) { return (flags[k] & fusion::schedule_flag::rest) != 0; };
  const auto settle = static_cast<std::size_t>(0.25 * fs);
  for (std::size_t k = 0; k < n;) {
    const bool at_rest = still(k);
    std::size_t e = k;
    while (e + 1 < n && still(e + 1) == at_rest) ++e;
    if (at_rest) {
      for (std::size_t s0 = k + settle; s0 + kSeg <= e + 1; s0 += kSeg / 2) add_segment(raw, s0, tr, rest);
    } else {
      for (std::size_t s0 = k + settle; s0 + kSeg + settle <= e + 1; s0 += kSeg / 2) add_segment(raw, s0, tr, moving);
    }
    k = e + 1;
  }
}

// What a set of spectra is read against: the sample rate, the window's power, g, and each
// sensor's noise floor from the data sheet ((m/s²)²/Hz, one-sided).
struct SpectrumScale {
  double fs_hz = 0.0, w2 = 0.0, g = 0.0;
  double floor[2] = {0.0, 0.0};  // table, head
};

// What the spectra show, summed over the sets analysed (the common test may read both).
struct SpectralFindings {
  double worst_common = 0.0, worst_diff = 0.0, disp_diff = 0.0, coh_sum = 0.0, coh_w = 0.0;
  double thr = 0.0;  // the last set's threshold over the floor
  std::vector<SpectralLine> common_lines, diff_lines;
};

// One axis of a set of spectra against its floor, bins f_lo ≤ f < f_hi.
void analyse_axis(const Spectra& S, int a, std::size_t f_lo, std::size_t f_hi, double scale, const SpectrumScale& sc,
                  bool differential, SpectralFindings& out) {
  const double df = sc.fs_hz / kSeg, g = sc.g, thr = out.thr;
  // The floor each signal really has: the data sheet times the median over the band (the
  // DAQ's own noise, a sensor better or worse than its sheet), never below the sheet's half.
  std::vector<double> rt, rh, rr;
  for (std::size_t f = f_lo; f < f_hi; ++f) {
    rt.push_back(S.pt[a][f] * scale / sc.floor[0]);
    rh.push_back(S.ph[a][f] * scale / sc.floor[1]);
    rr.push_back(S.pr[a][f] * scale / (sc.floor[0] + sc.floor[1]));
  }
  const double ft0 = sc.floor[0] * std::max(0.5, dsp::median(rt, 1.0)),
               fh0 = sc.floor[1] * std::max(0.5, dsp::median(rh, 1.0));
  const double fr0 = (sc.floor[0] + sc.floor[1]) * std::max(0.5, dsp::median(rr, 1.0));
  double ex_common = 0.0, ex_diff = 0.0, disp = 0.0;
  for (std::size_t f = f_lo; f < f_hi; ++f) {
    const double pt = S.pt[a][f] * scale, ph = S.ph[a][f] * scale, pr = S.pr[a][f] * scale;
    const double w = 2.0 * std::numbers::pi * static_cast<double>(f) * df;
    if (pr > thr * fr0 && f >= 2) {  // relative motion at this frequency (above the lowest bin: the last of a settling)
      if (!differential) continue;
      ex_diff += (pr - fr0) * df;
      disp += (pr - fr0) * df / (w * w * w * w);
      out.diff_lines.push_back({static_cast<double>(f) * df, pr / fr0, std::sqrt(2.0 * (pr - fr0) * df) / (g * 1e-3)});
    } else if (pt > thr * ft0 && ph > thr * fh0) {
      const double coh = std::norm(S.cth[a][f]) / std::max(1e-300, S.pt[a][f] * S.ph[a][f]);
      if (coh > 0.7 && pr < 0.1 * std::min(pt, ph)) {  // in both, in phase, cancelling in head − table
        ex_common += 0.5 * ((pt - ft0) + (ph - fh0)) * df;
        out.coh_sum += coh * pt, out.coh_w += pt;
        out.common_lines.push_back(
            {static_cast<double>(f) * df, std::min(pt / ft0, ph / fh0), std::sqrt(2.0 * (pt - ft0) * df) / (g * 1e-3)});
      }
    }
  }
  out.worst_common = std::max(out.worst_common, std::sqrt(ex_common) / (g * 1e-3));
  out.worst_diff = std::max(out.worst_diff, std::sqrt(ex_diff) / (g * 1e-3));
  out.disp_diff = std::max(out.disp_diff, std::sqrt(disp) * 1e6);
}

// One set of spectra against its floor: the common test, and the differential one if asked.
void analyse_spectra(const Spectra& S, double lo_hz, bool differential, const SpectrumScale& sc,
                     SpectralFindings& out) {
  const double fs = sc.fs_hz, df = fs / kSeg;
  const double scale = 2.0 / (fs * sc.w2 * S.segments);  // one-sided PSD, (m/s²)²/Hz
  out.thr = std::max(3.0, threshold(S.segments));
  const std::size_t f_lo = static_cast<std::size_t>(std::ceil(lo_hz / df)),
                    f_hi = static_cast<std::size_t>(0.45 * fs / df);
  for (int a = 0; a < 3; ++a) analyse_axis(S, a, f_lo, f_hi, scale, sc, differential, out);
}

// The strongest five lines.
void keep_top_lines(std::vector<SpectralLine>& v) {
  std::sort(v.begin(), v.end(), [](const auto& x, const auto& y) { return x.amp_mg > y.amp_mg; });
  if (v.size() > 5) v.resize(5);
}

void report_common(SpectralFindings& f, const std::string& where, VibrationFinding& out) {
  const std::size_t n_common = f.common_lines.size();
  keep_top_lines(f.common_lines);
  out.rms_mg = f.worst_common;
  out.coherence = f.coh_w > 0.0 ? f.coh_sum / f.coh_w : 0.0;
  out.lines = f.common_lines;
  out.found = !f.common_lines.empty();
  char buf[256];
  std::snprintf(
      buf, sizeof buf,
      "%zu bins above %.1fx the noise floor in both sensors, coherent (%.2f), cancelling in head - table; %.3f mg RMS",
      n_common, f.thr, out.coherence, f.worst_common);
  out.evidence = buf + where;
}

// The differential finding; its evidence only when the standstills were analysed.
void report_differential(SpectralFindings& f, bool rest_ok, VibrationFinding& out) {
  const std::size_t n_diff = f.diff_lines.size();
  keep_top_lines(f.diff_lines);
  out.rms_mg = f.worst_diff;
  out.displacement_um = f.disp_diff;
  out.lines = f.diff_lines;
  out.found = !f.diff_lines.empty();
  char buf[256];
  std::snprintf(buf, sizeof buf,
                "%zu bins of head - table above %.1fx its noise floor; %.3f mg RMS, %.3f um RMS displacement", n_diff,
                f.thr, f.worst_diff, f.disp_diff);
  if (rest_ok) out.evidence = buf;
}

}  // namespace

VibrationTests vibration_tests(const RunResiduals& run) {
  VibrationTests out;
  const auto& raw = run.measurement.raw;
  const std::size_t n = std::min(raw.schedule.flags.size(), raw.head_mps2.size());
  const double fs = run.fs_hz;
  SegmentTransform tr;
  Spectra rest, moving;
  collect_segments(raw, n, fs, tr, rest, moving);
  out.seconds_used = static_cast<double>(rest.segments) * kSeg / 2.0 / fs;
  SpectrumScale sc;
  sc.fs_hz = fs, sc.w2 = tr.w2, sc.g = run.meta.site.g_mps2;
  for (int s = 0; s < 2; ++s) {
    const double n_g = run.meta.sensors[s].noise_ug_per_rthz * 1e-6 * sc.g;
    sc.floor[s] = 2.0 * n_g * n_g;
  }
  out.floor_ug_per_rthz = std::hypot(run.meta.sensors[0].noise_ug_per_rthz, run.meta.sensors[1].noise_ug_per_rthz);
  SpectralFindings f;
  const bool rest_ok = rest.segments >= 2, moving_ok = moving.segments >= 4;
  std::string where;
  if (rest_ok) analyse_spectra(rest, kMinHz, true, sc, f);
  if (rest.segments < 4 && moving_ok && f.common_lines.empty()) {
    analyse_spectra(moving, kMotionMinHz, false, sc, f);
    where = " (during the motion, above " + std::to_string(static_cast<int>(kMotionMinHz)) + " Hz)";
  }
  if (!rest_ok && !moving_ok) {
    out.common.evidence = out.differential.evidence = "too little standstill or steady motion for a spectrum (" +
                                                      std::to_string(rest.segments) + " segments of 0.2 s)";
    return out;
  }
  if (!rest_ok)
    out.differential.evidence = "too little standstill for a spectrum of head - table (" +
                                std::to_string(rest.segments) + " segments of 0.2 s)";
  report_common(f, where, out.common);
  report_differential(f, rest_ok, out.differential);
  return out;
}

}  // namespace eical::dsp::model
