#include "tests/support/accuracy_campaign.hpp"

#include "dsp/analysis/analyze_run.hpp"
#include "dsp/eval/circle_segments.hpp"
#include "dsp/fusion/error_covariance.hpp"
#include "sim/simulate.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Dense>
#include <Eigen/Geometry>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <random>

namespace eical::tools::accuracy {
namespace {

std::string fmt(const char* f, double a, double b = 0.0, double c = 0.0) {
  char buf[160];
  std::snprintf(buf, sizeof buf, f, a, b, c);
  return buf;
}

// The sensors as they really are: data sheet ± the tolerances, drawn per seed.
void draw_sensor(sim::SensorTruth& t, const dsp::SensorSpec& sheet, std::mt19937_64& rng, const char* name,
                 std::vector<std::string>& text) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  t.spec = sheet;
  Eigen::Vector3d scale;
  for (int i = 0; i < 3; ++i) scale[i] = 0.005 * u(rng), t.spec.k1_v_per_g[i] *= 1.0 + scale[i];
  t.spec.f0_hz *= 1.0 + 0.1 * u(rng);
  t.spec.zeta = 0.65 + 0.15 * u(rng);
  const double r2 = u(rng), r1 = u(rng), r0 = u(rng);  // in order: a call's arguments have none
  const Eigen::Vector3d r = Eigen::Vector3d(r0, r1, r2) * 5e-3;
  const Eigen::Matrix3d rot =
      (Eigen::AngleAxisd(r[2], Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(r[1], Eigen::Vector3d::UnitY()) *
       Eigen::AngleAxisd(r[0], Eigen::Vector3d::UnitX()))
          .toRotationMatrix();
  t.spec.to_machine = sheet.to_machine * rot;
  t.bias_rw_ug_per_rts = 0.15;
  text.push_back(std::string(name) + ": scale " + fmt("%+.0f %+.0f ", scale[0] * 1e6, scale[1] * 1e6) +
                 fmt("%+.0f ppm, ", scale[2] * 1e6) + fmt("f0 %.0f Hz, zeta %.3f, ", t.spec.f0_hz, t.spec.zeta) +
                 fmt("rotation %+.2f %+.2f ", r[0] * 1e3, r[1] * 1e3) +
                 fmt("%+.2f mrad, bias walk 0.15 ug/rt(s)", r[2] * 1e3));
}

// One machine for all programs: its sensors, position loops with 99 % feed-forward, PSD
// configuration B; the ideal reference is the truth the figures are taken against.
struct Machine {
  sim::SensorTruth truth[2];
  void apply(sim::Scenario& sc, bool reference) const {
    for (int s = 0; s < 2; ++s) sc.truth[s] = truth[s];
    for (auto& a : sc.machine.servo) a = sim::AxisServo{34.0, 0.99, 0.0};
    sc.meta.psd = sim::psd_config_b(10.0);
    if (!reference) sc.meta.reference.reset();
  }
};

std::string step_gcode() {
  std::string g =
      "G90 G21 G17 G61 (1-D move 50 mm at 6.5 m/min, 5 runs, across the x strip)\nG0 X-25 Y-10\nG4 P0.4\nM101\nG4 "
      "P0.1\n";
  for (int r = 0; r < 5; ++r) g += "G1 X25 F6500\nM102\nG4 P0.5\nG1 X-25 F6500\nM102\nG4 P0.5\n";
  return g + "G4 P0.4\nM103\nG4 P0.1\n";
}

std::string rectangle_gcode() {
  std::string g =
      "G90 G21 G17 G61 (rectangle 50 mm at 6.5 m/min across both strips)\nG0 X-40 Y-10\nG4 P0.4\nM101\nG4 P0.1\n";
  for (const char* c : {"X10 Y-10", "X10 Y40", "X-40 Y40", "X-40 Y-10"})
    g += std::string("G1 ") + c + " F6500\nM102\nG4 P0.5\n";
  return g + "G4 P0.4\nM103\nG4 P0.1\n";
}

// Expected largest |e| of a zero-mean Gaussian vector with covariance c (Monte Carlo).
double expected_peak(const Eigen::MatrixXd& c, std::uint64_t seed) {
  const Eigen::Index n = c.rows();
  if (n == 0) return 0.0;
  const Eigen::LLT<Eigen::MatrixXd> llt(c + 1e-12 * c.diagonal().mean() * Eigen::MatrixXd::Identity(n, n));
  const Eigen::MatrixXd l = llt.matrixL();
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g;
  double sum = 0.0;
  const int draws = 400;
  Eigen::VectorXd z(n);
  for (int d = 0; d < draws; ++d) {
    for (Eigen::Index i = 0; i < n; ++i) z[i] = g(rng);
    sum += (l * z).cwiseAbs().maxCoeff();
  }
  return sum / draws;
}

struct Analysed {
  dsp::Run run;
  dsp::Analysis a;
  std::unique_ptr<dsp::fusion::ErrorCovariance> cov;
  std::ptrdiff_t shift = 0;  // sensor-time trace position = aligned trace position + shift
};

Analysed analyse(const sim::Scenario& sc, const Report& rep) {
  Analysed r;
  r.run = sim::simulate(sc);
  if (rep.calibrated) dsp::identify::apply_identification(rep.identification, r.run.meta);
  if (rep.oracle)
    for (int s = 0; s < 2; ++s) r.run.meta.sensors[s] = sc.truth[s].spec;
  dsp::AnalysisOptions o;
  o.keep_raw = true;
  o.uncertainty.enabled = false;  // the campaign's own bound is the point here
  if (rep.calibrated || rep.oracle) o.sensor_model = rep.oracle ? "oracle" : "psd";
  r.a = dsp::analyze_run(r.run, o);
  const auto& m = r.a.measurement;
  const dsp::PipelineConfig cfg = dsp::pipeline_config(r.run.meta, r.run.frames.size());
  r.cov = std::make_unique<dsp::fusion::ErrorCovariance>(m.raw.schedule, m.sample_index, m.fs_hz, cfg.fusion,
                                                         m.supports.start_bias_sigma_um_s2);
  r.shift = static_cast<std::ptrdiff_t>(std::lround(r.run.meta.acquisition.daq_group_delay_samples));
  return r;
}

// Trace positions (aligned) of the second half of the dwell after each M102 until the set-
// point moves again: where the end positions and corners are read.
std::vector<std::pair<std::size_t, std::size_t>> dwell_windows(const dsp::Measurement& m) {
  std::vector<std::pair<std::size_t, std::size_t>> w;
  for (const auto& t : m.triggers) {
    if (t.code != dsp::trigger::segment_mark) continue;
    const auto it = std::lower_bound(m.sample_index.begin(), m.sample_index.end(), t.sample_index);
    if (it == m.sample_index.end()) continue;
    const auto k = static_cast<std::size_t>(it - m.sample_index.begin());
    std::size_t e = k;
    while (e + 1 < m.cmd_mm.size() && (m.cmd_mm[e + 1] - m.cmd_mm[k]).cwiseAbs().maxCoeff() < 1e-9) ++e;
    if (e > k + 20) w.push_back({k + (e - k) / 2, e});
  }
  return w;
}

// Sensor-time grid points of a dwell window (every 10th sample) and the averaging row.
void dwell_grid(const std::pair<std::size_t, std::size_t>& w, std::ptrdiff_t shift, std::size_t limit,
                std::vector<std::size_t>& grid) {
  for (std::size_t k = w.first; k <= w.second; k += 10) {
    const auto s = static_cast<std::ptrdiff_t>(k) + shift;
    if (s >= 0 && static_cast<std::size_t>(s) < limit) grid.push_back(static_cast<std::size_t>(s));
  }
}

// The radius deviation's error against the reference: over every point, and of the mean
// over the revolutions (1° bins).
struct CircleErrors {
  double rms = 0.0, peak = 0.0, rms_avg = 0.0, peak_avg = 0.0;
};

CircleErrors circle_errors(const dsp::Analysis& a) {
  const auto& dm = a.circle->trace.radius_deviation_um;
  const auto& dr = a.circle_reference->trace.radius_deviation_um;
  const auto& ang = a.circle->trace.angle_deg;
  double ss = 0.0, peak = 0.0;
  std::vector<double> bin_sum(360, 0.0), bin_n(360, 0.0);
  for (std::size_t i = 0; i < dm.size() && i < dr.size(); ++i) {
    const double e = dm[i] - dr[i];
    ss += e * e, peak = std::max(peak, std::abs(e));
    const auto b = static_cast<std::size_t>(std::clamp(std::floor(ang[i]), 0.0, 359.0));
    bin_sum[b] += e, bin_n[b] += 1.0;
  }
  const double rms = std::sqrt(ss / static_cast<double>(dm.size()));
  double ss_avg = 0.0, peak_avg = 0.0, nb = 0.0;
  for (std::size_t b = 0; b < 360; ++b)
    if (bin_n[b] > 0.0) {
      const double e = bin_sum[b] / bin_n[b];
      ss_avg += e * e, peak_avg = std::max(peak_avg, std::abs(e)), nb += 1.0;
    }
  const double rms_avg = std::sqrt(ss_avg / nb);
  return {rms, peak, rms_avg, peak_avg};
}

constexpr int kBoundPointsPerRev = 180;

// Where the bound looks: 180 points per revolution (sensor-time trace positions), each
// with its angle and revolution.
struct RevolutionGrid {
  std::vector<std::size_t> grid;
  std::vector<double> theta;
  std::vector<int> rev;
  int revs = 0;
};

RevolutionGrid revolution_grid(const dsp::Measurement& m, std::ptrdiff_t shift) {
  std::vector<Eigen::Vector2d> cmd;
  for (const auto& c : m.cmd_mm) cmd.emplace_back(c.x(), c.y());
  std::vector<std::int64_t> marks;
  for (const auto& t : m.triggers)
    if (t.code == dsp::trigger::segment_mark) marks.push_back(t.sample_index);
  const auto segs = dsp::eval::find_circle_segments(cmd, m.sample_index, marks, Eigen::Vector2d::Zero(), 360.0);
  RevolutionGrid rg;
  const int per_rev = kBoundPointsPerRev;
  for (std::size_t s = 0; s < segs.size(); ++s) {
    const auto b = static_cast<std::size_t>(segs[s].begin_index - m.sample_index.front());
    const auto e = static_cast<std::size_t>(segs[s].end_index - m.sample_index.front());
    for (int g = 0; g < per_rev; ++g) {
      const std::size_t k = b + (e - b) * static_cast<std::size_t>(g) / per_rev;
      const auto ks = static_cast<std::ptrdiff_t>(k) + shift;
      if (ks < 0 || static_cast<std::size_t>(ks) >= m.raw.schedule.flags.size()) continue;
      rg.grid.push_back(static_cast<std::size_t>(ks));
      rg.theta.push_back(std::atan2(m.cmd_mm[k].y(), m.cmd_mm[k].x()));
      rg.rev.push_back(static_cast<int>(s));
    }
  }
  rg.revs = static_cast<int>(segs.size());
  return rg;
}

// What each revolution's centre fit takes out (its cos/sin components): block-diagonal
// I − B(BᵀB)⁻¹Bᵀ per revolution.
Eigen::MatrixXd centre_fit_projection(const Eigen::VectorXd& cs, const Eigen::VectorXd& sn, const RevolutionGrid& rg) {
  const auto n = static_cast<Eigen::Index>(rg.grid.size());
  Eigen::MatrixXd proj = Eigen::MatrixXd::Zero(n, n);
  for (int s = 0; s < rg.revs; ++s) {
    std::vector<Eigen::Index> idx;
    for (Eigen::Index i = 0; i < n; ++i)
      if (rg.rev[static_cast<std::size_t>(i)] == s) idx.push_back(i);
    const auto ni = static_cast<Eigen::Index>(idx.size());
    Eigen::MatrixXd bm(ni, 2);
    for (Eigen::Index i = 0; i < ni; ++i)
      bm(i, 0) = cs[idx[static_cast<std::size_t>(i)]], bm(i, 1) = sn[idx[static_cast<std::size_t>(i)]];
    const Eigen::MatrixXd p = Eigen::MatrixXd::Identity(ni, ni) - bm * (bm.transpose() * bm).inverse() * bm.transpose();
    for (Eigen::Index i = 0; i < ni; ++i)
      for (Eigen::Index j = 0; j < ni; ++j)
        proj(idx[static_cast<std::size_t>(i)], idx[static_cast<std::size_t>(j)]) = p(i, j);
  }
  return proj;
}

// The noise-limited bound of the radius deviation's error as quadratic forms of the
// posterior covariance: of every point (cp) and of the mean over the revolutions (ca).
struct CircleBound {
  Eigen::MatrixXd cp, ca;
  double rms = 0.0, rms_avg = 0.0;
};

CircleBound circle_bound(const Analysed& r) {
  const RevolutionGrid rg = revolution_grid(r.a.measurement, r.shift);
  const int per_rev = kBoundPointsPerRev;
  const auto n = static_cast<Eigen::Index>(rg.grid.size());
  const Eigen::MatrixXd cx = r.cov->position(rg.grid, 0), cy = r.cov->position(rg.grid, 1);
  Eigen::VectorXd cs(n), sn(n);
  for (Eigen::Index i = 0; i < n; ++i)
    cs[i] = std::cos(rg.theta[static_cast<std::size_t>(i)]), sn[i] = std::sin(rg.theta[static_cast<std::size_t>(i)]);
  const Eigen::MatrixXd ce = cs.asDiagonal() * cx * cs.asDiagonal() + sn.asDiagonal() * cy * sn.asDiagonal();
  const Eigen::MatrixXd proj = centre_fit_projection(cs, sn, rg);
  const Eigen::MatrixXd cp = proj * ce * proj.transpose();
  const double bound_rms = std::sqrt(cp.trace() / static_cast<double>(n));
  // The mean over the revolutions at each grid angle.
  Eigen::MatrixXd avg = Eigen::MatrixXd::Zero(per_rev, n);
  for (Eigen::Index i = 0; i < n; ++i) avg(i % per_rev, i) = 1.0 / rg.revs;
  const Eigen::MatrixXd ca = avg * cp * avg.transpose();
  const double bound_avg = std::sqrt(ca.trace() / per_rev);
  return {cp, ca, bound_rms, bound_avg};
}

void circle_figures(const Machine& mach, Report& rep) {
  sim::Scenario sc = sim::circle_scenario(10.0, 2500.0, 5, "ccw", rep.seed);
  mach.apply(sc, true);
  const Analysed r = analyse(sc, rep);
  if (!r.a.circle || !r.a.circle_reference) {
    rep.figures.push_back({"circle R10: evaluation failed", "um", 1e9, 0.0, 1.5});
    return;
  }
  const CircleErrors e = circle_errors(r.a);
  // Bound: the radial error at 180 points per revolution, less what each revolution's centre
  // fit takes out (its cos/sin components), as a quadratic form of the posterior covariance.
  const CircleBound b = circle_bound(r);
  rep.figures.push_back(
      {"circle R10 2.5 m/min x5: radius deviation error RMS (every revolution)", "um", e.rms, b.rms, 1.5});
  rep.figures.push_back({"circle R10 2.5 m/min x5: radius deviation error peak (every revolution)", "um", e.peak,
                         expected_peak(b.cp, rep.seed), 3.0});
  rep.figures.push_back(
      {"circle R10 2.5 m/min x5: mean of the 5 revolutions, error RMS", "um", e.rms_avg, b.rms_avg, 1.5});
  rep.figures.push_back({"circle R10 2.5 m/min x5: mean of the 5 revolutions, error peak", "um", e.peak_avg,
                         expected_peak(b.ca, rep.seed + 1), 3.0});
}

void step_figures(const Machine& mach, Report& rep) {
  sim::Scenario sc = sim::gcode_scenario(step_gcode(), eical::dsp::ProgramKind::step, rep.seed);
  auto& p = sc.meta.program;
  p.axis = "x", p.targets_mm = {-25.0, 25.0}, p.feed_mm_min = 6500.0, p.runs = 5, p.dwell_s = 0.5;
  mach.apply(sc, true);
  const Analysed r = analyse(sc, rep);
  const auto& m = r.a.measurement;
  const auto windows = dwell_windows(m);
  std::vector<double> far, all;
  std::vector<std::size_t> grid;
  std::vector<std::pair<Eigen::Index, Eigen::Index>> spans;  // per far arrival: [begin, end) in grid
  for (const auto& w : windows) {
    double e = 0.0;
    for (std::size_t k = w.first; k <= w.second; ++k) e += (m.pos_mm[k].x() - m.ref_mm[k].x()) * 1000.0;
    e /= static_cast<double>(w.second - w.first + 1);
    all.push_back(e);
    if (m.cmd_mm[w.first].x() > 0.0) {
      far.push_back(e);
      const auto b = static_cast<Eigen::Index>(grid.size());
      dwell_grid(w, r.shift, m.raw.schedule.flags.size(), grid);
      spans.push_back({b, static_cast<Eigen::Index>(grid.size())});
    }
  }
  if (far.size() < 2) {
    rep.figures.push_back({"1-D move: evaluation failed", "um", 1e9, 0.0, 2.0});
    return;
  }
  double mean = 0.0;
  for (double e : far) mean += e;
  mean /= static_cast<double>(far.size());
  double var = 0.0, worst = 0.0;
  for (double e : far) var += (e - mean) * (e - mean);
  for (double e : all) worst = std::max(worst, std::abs(e));
  const double scatter = 2.0 * std::sqrt(var / static_cast<double>(far.size() - 1));
  // Bound: each arrival's dwell mean and the mean over the arrivals, from the covariance.
  const Eigen::MatrixXd c = r.cov->position(grid, 0);
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(spans.size()), c.rows());
  for (std::size_t i = 0; i < spans.size(); ++i)
    for (Eigen::Index j = spans[i].first; j < spans[i].second; ++j)
      a(static_cast<Eigen::Index>(i), j) = 1.0 / static_cast<double>(spans[i].second - spans[i].first);
  const Eigen::MatrixXd ce = a * c * a.transpose();
  const Eigen::RowVectorXd mean_row = Eigen::RowVectorXd::Constant(ce.rows(), 1.0 / static_cast<double>(ce.rows()));
  const double bound_mean = std::sqrt((mean_row * ce * mean_row.transpose())(0));
  // Scatter of the arrivals about their mean: E[Σ(e_i − ē)²/(n−1)] = (tr C − 1ᵀC1/n)/(n−1).
  const double nn = static_cast<double>(ce.rows());
  const double bound_scatter = 2.0 * std::sqrt(std::max(0.0, (ce.trace() - ce.sum() / nn) / (nn - 1.0)));
  rep.figures.push_back(
      {"1-D move 50 mm 6.5 m/min x5: end-position error |mean| at the far end", "um", std::abs(mean), bound_mean, 2.0});
  rep.figures.push_back(
      {"1-D move 50 mm 6.5 m/min x5: scatter of the end positions (2 sigma)", "um", scatter, bound_scatter, 2.0});
  rep.figures.push_back(
      {"1-D move 50 mm 6.5 m/min x5: largest error of any arrival", "um", worst, expected_peak(ce, rep.seed + 2), 3.0});
}

void rectangle_figures(const Machine& mach, Report& rep) {
  sim::Scenario sc = sim::gcode_scenario(rectangle_gcode(), eical::dsp::ProgramKind::rectangle, rep.seed);
  auto& p = sc.meta.program;
  p.corner_mm[0] = -40.0, p.corner_mm[1] = -10.0, p.size_mm[0] = 50.0, p.size_mm[1] = 50.0, p.feed_mm_min = 6500.0,
  p.dwell_s = 0.5;
  mach.apply(sc, true);
  const Analysed r = analyse(sc, rep);
  const auto& m = r.a.measurement;
  const auto windows = dwell_windows(m);
  std::vector<std::size_t> grid;
  std::vector<std::pair<Eigen::Index, Eigen::Index>> spans;
  double worst = 0.0, ss = 0.0;
  for (const auto& w : windows) {
    Eigen::Vector2d e = Eigen::Vector2d::Zero();
    for (std::size_t k = w.first; k <= w.second; ++k) e += (m.pos_mm[k] - m.ref_mm[k]).head<2>() * 1000.0;
    e /= static_cast<double>(w.second - w.first + 1);
    worst = std::max(worst, e.norm()), ss += e.squaredNorm();
    const auto b = static_cast<Eigen::Index>(grid.size());
    dwell_grid(w, r.shift, m.raw.schedule.flags.size(), grid);
    spans.push_back({b, static_cast<Eigen::Index>(grid.size())});
  }
  if (windows.empty()) {
    rep.figures.push_back({"rectangle: evaluation failed", "um", 1e9, 0.0, 3.0});
    return;
  }
  const auto nc = static_cast<Eigen::Index>(spans.size());
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(nc, static_cast<Eigen::Index>(grid.size()));
  for (Eigen::Index i = 0; i < nc; ++i)
    for (Eigen::Index j = spans[static_cast<std::size_t>(i)].first; j < spans[static_cast<std::size_t>(i)].second; ++j)
      a(i, j) = 1.0 / static_cast<double>(spans[static_cast<std::size_t>(i)].second -
                                          spans[static_cast<std::size_t>(i)].first);
  const Eigen::MatrixXd cx = a * r.cov->position(grid, 0) * a.transpose(),
                        cy = a * r.cov->position(grid, 1) * a.transpose();
  Eigen::MatrixXd joint = Eigen::MatrixXd::Zero(2 * nc, 2 * nc);
  joint.topLeftCorner(nc, nc) = cx, joint.bottomRightCorner(nc, nc) = cy;
  // Expected largest corner error |(ex, ey)| by drawing the pair per corner.
  const Eigen::LLT<Eigen::MatrixXd> llt(joint + 1e-12 * Eigen::MatrixXd::Identity(2 * nc, 2 * nc));
  const Eigen::MatrixXd l = llt.matrixL();
  std::mt19937_64 rng(rep.seed + 3);
  std::normal_distribution<double> g;
  double peak_sum = 0.0;
  Eigen::VectorXd z(2 * nc);
  for (int d = 0; d < 400; ++d) {
    for (Eigen::Index i = 0; i < 2 * nc; ++i) z[i] = g(rng);
    const Eigen::VectorXd e = l * z;
    double mx = 0.0;
    for (Eigen::Index i = 0; i < nc; ++i) mx = std::max(mx, std::hypot(e[i], e[nc + i]));
    peak_sum += mx;
  }
  rep.figures.push_back({"rectangle 50 mm 6.5 m/min: largest corner error", "um", worst, peak_sum / 400.0, 3.0});
  rep.figures.push_back({"rectangle 50 mm 6.5 m/min: corner error RMS", "um", std::sqrt(ss / static_cast<double>(nc)),
                         std::sqrt((cx.trace() + cy.trace()) / static_cast<double>(nc)), 3.0});
}

}  // namespace

Report run(const Options& options) {
  const auto t0 = std::chrono::steady_clock::now();
  Report rep;
  rep.seed = options.seed;
  std::mt19937_64 rng(sim::stream_seed(options.seed, 900));
  Machine mach;
  const dsp::RunMeta sheet;
  draw_sensor(mach.truth[0], sheet.sensors[0], rng, "table", rep.truth);
  draw_sensor(mach.truth[1], sheet.sensors[1], rng, "head", rep.truth);
  rep.oracle = options.oracle;
  if (options.calibrate && !options.oracle) {  // on site: the identification program, PSD and set-point only
    sim::Scenario id = sim::identify_scenario(sim::psd_config_b(10.0), {"z"}, options.seed);
    mach.apply(id, false);
    rep.identification = dsp::identify::identify_sensors(sim::simulate(id));
    rep.calibrated = true;
  }
  circle_figures(mach, rep);
  step_figures(mach, rep);
  rectangle_figures(mach, rep);
  rep.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return rep;
}

std::string table(const Report& report) {
  std::string o = "accuracy campaign, seed " + std::to_string(report.seed) +
                  (report.oracle       ? ", the true sensor parameters (oracle)"
                   : report.calibrated ? ", sensors identified on site"
                                       : ", data-sheet sensors") +
                  "\n";
  for (const auto& t : report.truth) o += "  true " + t + "\n";
  if (report.calibrated) {
    const auto& id = report.identification;
    o += fmt("  identification: agreement with the PSD readings %.2f -> %.2f um RMS, ", id.psd_rms_before_um,
             id.psd_rms_after_um) +
         fmt("DAQ delay %.3f samples ", id.daq_group_delay_samples) +
         (id.delay_identified ? "(identified)\n" : "(data sheet kept)\n");
  }
  char line[256];
  std::snprintf(line, sizeof line, "  %-72s %9s %9s %7s %7s\n", "figure", "measured", "bound", "ratio", "target");
  o += line;
  for (const auto& f : report.figures) {
    std::snprintf(line, sizeof line, "  %-72s %6.2f %s %6.2f %s %7.2f %5.1f %s%s\n", f.name.c_str(), f.measured,
                  f.unit.c_str(), f.bound, f.unit.c_str(), f.ratio(), f.target, f.unit.c_str(),
                  f.within() ? "" : "  OVER");
    o += line;
  }
  o += fmt("  campaign wall time %.1f s\n", report.seconds);
  return o;
}

}  // namespace eical::tools::accuracy
