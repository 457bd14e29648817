#include "dsp/identify/delay_estimate.hpp"

#include "dsp/core/interpolate.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>

namespace eical::dsp::identify {
namespace {

// The regression: per used fix a row [per strip: offset, direction | velocity] (row-major),
// y = reading − c(k − d0) in mm, and the pass over the strip it belongs to.
struct DelayRows {
  int p = 0;  // columns: 2 × strips + 1
  std::vector<double> rows, ys;
  std::vector<int> pass_of;
  int passes = 0;
};

// Every 10th fix of the strips, where c is known around k − d0 and moves faster than 1 mm/s.
DelayRows delay_rows(const std::vector<fusion::PositionFix>& fixes, const std::vector<Eigen::Vector3d>& c, int strips,
                     double d0, double fs) {
  DelayRows d;
  d.p = 2 * strips + 1;
  const int p = d.p;
  std::size_t last_k = 0;
  int count = 0;
  for (const auto& fx : fixes) {
    if (fx.strip < 0 || fx.strip >= strips) continue;
    if (fx.k != last_k + 1) ++d.passes;
    last_k = fx.k;
    if (count++ % 10 != 0) continue;
    const double pos = static_cast<double>(fx.k) - d0;
    if (pos < 1.0 || pos + 2.0 >= static_cast<double>(c.size())) continue;
    const double ref = interpolate_at(c, pos, fx.axis);
    const double v =
        (interpolate_at(c, pos + 1.0, fx.axis) - interpolate_at(c, pos - 1.0, fx.axis)) / 2.0 * fs;  // mm/s
    if (!std::isfinite(ref) || !std::isfinite(v) || std::abs(v) < 1.0) continue;
    std::vector<double> r(static_cast<std::size_t>(p), 0.0);
    r[static_cast<std::size_t>(2 * fx.strip)] = 1.0;
    r[static_cast<std::size_t>(2 * fx.strip + 1)] = v > 0.0 ? 1.0 : -1.0;
    r[static_cast<std::size_t>(p - 1)] = v;
    d.rows.insert(d.rows.end(), r.begin(), r.end());
    d.ys.push_back(fx.position_um / 1000.0 - ref);
    d.pass_of.push_back(d.passes);
  }
  return d;
}

// Only the columns that vary (a strip never crossed leaves its offset empty).
// Only what this run's crossings can tell apart. A strip crossed at one speed one way (a
// circle's tangent strips) cannot separate its mounting offset from the lag: the strip is
// then taken where run.toml puts it (mounting_assumed). The direction term (backlash) needs
// both directions at more than one speed. The velocity column last.
std::vector<Eigen::Index> identifiable_columns(const Eigen::MatrixXd& a, int strips, bool& mounting_assumed) {
  const Eigen::Index n = a.rows(), p = a.cols();
  std::vector<Eigen::Index> used;
  for (int st = 0; st < strips; ++st) {
    std::vector<double> sp;
    bool pos = false, neg = false;
    for (Eigen::Index i = 0; i < n; ++i)
      if (a(i, 2 * st) != 0.0) sp.push_back(std::abs(a(i, p - 1))), (a(i, p - 1) > 0.0 ? pos : neg) = true;
    if (sp.empty()) continue;
    double mean = 0.0, var = 0.0;
    for (double x : sp) mean += x;
    mean /= static_cast<double>(sp.size());
    for (double x : sp) var += (x - mean) * (x - mean);
    const bool speeds = std::sqrt(var / static_cast<double>(sp.size())) > 0.2 * mean;
    if (speeds || (pos && neg)) used.push_back(2 * st);
    if (speeds && pos && neg) used.push_back(2 * st + 1);
    if (!(speeds || (pos && neg))) mounting_assumed = true;
  }
  used.push_back(p - 1);
  return used;
}

// σ of the last coefficient. Neighbouring readings of a pass share its errors (the spot's
// path, vibration): the covariance is clustered by pass (sandwich estimator, small-sample
// factor c/(c − 1)), and never below the white-noise one.
double clustered_sigma_of_last(const Eigen::MatrixXd& au, const Eigen::VectorXd& res, const std::vector<int>& pass_of) {
  const Eigen::Index n = au.rows();
  const Eigen::MatrixXd bread = (au.transpose() * au).inverse();
  Eigen::MatrixXd meat = Eigen::MatrixXd::Zero(au.cols(), au.cols());
  int clusters = 0;
  for (Eigen::Index i = 0; i < n;) {
    Eigen::VectorXd score = Eigen::VectorXd::Zero(au.cols());
    const int pass = pass_of[static_cast<std::size_t>(i)];
    for (; i < n && pass_of[static_cast<std::size_t>(i)] == pass; ++i) score += au.row(i).transpose() * res[i];
    meat += score * score.transpose(), ++clusters;
  }
  const double dof = static_cast<double>(n - au.cols());
  const Eigen::MatrixXd white = bread * (res.squaredNorm() / dof);
  const Eigen::MatrixXd clustered =
      bread * meat * bread * (clusters > 1 ? static_cast<double>(clusters) / (clusters - 1) : 1.0);
  const Eigen::Index iv = au.cols() - 1;
  return std::sqrt(std::max({0.0, white(iv, iv), clustered(iv, iv)}));
}

}  // namespace

DelayEstimate estimate_delay(const Measurement& m, const RunMeta& meta, DelayReference against) {
  DelayEstimate d;
  d.against = against == DelayReference::setpoint ? "set-point" : "reference";
  const auto& fixes = m.raw.schedule.fixes;
  const auto& c = against == DelayReference::setpoint ? m.cmd_mm : m.ref_mm;
  const int strips = static_cast<int>(meta.psd.size());
  if (fixes.empty() || c.size() < 3 || strips == 0) return d;
  const double d0 = meta.acquisition.daq_group_delay_samples, fs = m.fs_hz;
  const DelayRows rows = delay_rows(fixes, c, strips, d0, fs);
  const int p = rows.p;
  const auto n = static_cast<Eigen::Index>(rows.ys.size());
  if (n < p + 4 || rows.passes < 2) return d;
  const Eigen::MatrixXd a =
      Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(rows.rows.data(), n, p);
  const Eigen::VectorXd y = Eigen::Map<const Eigen::VectorXd>(rows.ys.data(), n);
  const std::vector<Eigen::Index> used = identifiable_columns(a, strips, d.mounting_assumed);
  Eigen::MatrixXd au(n, static_cast<Eigen::Index>(used.size()));
  for (std::size_t j = 0; j < used.size(); ++j) au.col(static_cast<Eigen::Index>(j)) = a.col(used[j]);
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(au);
  if (qr.rank() < au.cols()) return d;
  const Eigen::VectorXd beta = qr.solve(y);
  const Eigen::VectorXd res = y - au * beta;
  d.samples = d0 - beta[au.cols() - 1] * fs;
  d.sigma = clustered_sigma_of_last(au, res, rows.pass_of) * fs;
  d.fixes = static_cast<int>(n);
  d.valid = std::isfinite(d.samples);
  return d;
}

}  // namespace eical::dsp::identify
