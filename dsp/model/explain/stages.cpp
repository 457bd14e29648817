#include "dsp/model/explain/stages.hpp"

#include "dsp/core/central_difference.hpp"
#include "dsp/model/extension.hpp"

#include <algorithm>
#include <cmath>

namespace eical::dsp::model::stage {

ExplainedEffect* ExplainState::find(std::string_view name) {
  for (auto& e : effects)
    if (e.name == name) return &e;
  return nullptr;
}

const ExplainedEffect* ExplainState::find(std::string_view name) const {
  for (const auto& e : effects)
    if (e.name == name) return &e;
  return nullptr;
}

void ExplainState::merge(ExplainedEffect e) { stage::merge(effects, std::move(e)); }

void merge(std::vector<ExplainedEffect>& all, ExplainedEffect e) {
  for (auto& a : all) {
    if (a.name != e.name) continue;
    const bool take =
        (e.significant && !a.significant) || (e.significant == a.significant && e.importance_um > a.importance_um);
    for (const auto& [k, v] : (take ? a : e).params) (take ? e : a).params.emplace(k, v);
    if (take) a = std::move(e);
    return;
  }
  all.push_back(std::move(e));
}

ExplainedEffect effect_of(Effect e) {
  ExplainedEffect x;
  const EffectInfo& i = info(e);
  x.name = std::string(i.name), x.unit = std::string(i.unit), x.tolerance = i.tolerance;
  return x;
}

Eigen::VectorXd ExplainState::machine_projected(const Eigen::VectorXd& column_um) const {
  const Eigen::MatrixXd& q = leftover.machine_basis;
  const Eigen::VectorXd& sigma = leftover.machine_sigma_um;
  if (q.rows() != column_um.size() || sigma.size() != column_um.size()) return column_um;
  const Eigen::VectorXd w = column_um.cwiseQuotient(sigma);
  return (w - q * (q.transpose() * w)).cwiseProduct(sigma);
}

std::map<std::string, double> toward_zero(const std::map<std::string, double>& value,
                                          const std::map<std::string, double>& sigma, double k) {
  std::map<std::string, double> out = value;
  for (auto& [name, x] : out)
    if (const auto sg = sigma.find(name); sg != sigma.end()) x = toward_zero(x, k * sg->second);
  return out;
}

std::map<std::string, double> away_from_zero(const std::map<std::string, double>& value,
                                             const std::map<std::string, double>& sigma, double k) {
  std::map<std::string, double> out = value;
  for (auto& [name, x] : out)
    if (const auto sg = sigma.find(name); sg != sigma.end()) x = away_from_zero(x, k * sg->second);
  return out;
}

double magnitude_sigma(double magnitude, double toward, double away) {
  const double m = std::abs(magnitude);
  return 0.5 * std::max(std::abs(away) - m, m - std::abs(toward));
}

std::optional<double> axes_mean(const std::map<std::string, double>& value, const std::string& name) {
  double sum = 0.0;
  int cnt = 0;
  for (const auto& [k, x] : value)
    if (k == name || k.rfind(name + "@", 0) == 0) sum += x, ++cnt;
  if (cnt == 0) return std::nullopt;
  return sum / cnt;
}

// An effect's columns on this channel's rows (µm per unit).
Eigen::MatrixXd columns_on(const EffectModel& e, const Channel& ch) {
  Eigen::MatrixXd m(ch.rows(), static_cast<Eigen::Index>(e.columns.size()));
  for (std::size_t p = 0; p < e.columns.size(); ++p)
    for (Eigen::Index i = 0; i < ch.rows(); ++i)
      m(i, static_cast<Eigen::Index>(p)) =
          e.columns[p](ch.sample[static_cast<std::size_t>(i)], ch.axis[static_cast<std::size_t>(i)]);
  return m;
}

// The mode is driven by the axis' actual acceleration, the set-point's through its position
// loop: to first order a_cmd − τ·ȧ_cmd, so each drive has two columns.
std::vector<Eigen::VectorXd> mode_displacement_columns(const RunResiduals& rr, const Channel& rows, double f_hz,
                                                       double zeta) {
  std::vector<Eigen::VectorXd> cols;
  const double fs = 1.0 / rr.dt_s;
  const Eigen::Index n = rows.rows();
  for (int j = 0; j < 3; ++j) {
    if (!rr.moving[j]) continue;
    const Eigen::VectorXd& a_j = rr.a_cmd.col(j);
    for (const Eigen::VectorXd& drive : {a_j, central_difference(a_j, fs)}) {
      const Eigen::VectorXd m_mm = mode_response(drive, fs, f_hz, zeta, true);
      for (int a = 0; a < 3; ++a) {
        Eigen::VectorXd c = Eigen::VectorXd::Zero(n);
        for (Eigen::Index i = 0; i < n; ++i)
          if (rows.axis[static_cast<std::size_t>(i)] == a)
            c[i] = m_mm[rows.sample[static_cast<std::size_t>(i)]] * 1000.0;
        if (c.norm() > 0.0) cols.push_back(c);
      }
    }
  }
  return cols;
}

// A channel's residual with each axis' offset taken out (the reference's zero is arbitrary).
Eigen::VectorXd offsets_out(const Channel& ch) {
  Eigen::VectorXd v = ch.residual_um;
  for (int a = 0; a < 3; ++a) {
    double sum = 0.0;
    int cnt = 0;
    for (Eigen::Index i = 0; i < ch.rows(); ++i)
      if (ch.axis[static_cast<std::size_t>(i)] == a) sum += v[i], ++cnt;
    for (Eigen::Index i = 0; i < ch.rows(); ++i)
      if (cnt && ch.axis[static_cast<std::size_t>(i)] == a) v[i] -= sum / cnt;
  }
  return v;
}

// RMS over the rows of the axes the program moves.
double moving_axes_rms(const RunResiduals& rr, const Eigen::VectorXd& v, const Channel& ch) {
  double sum = 0.0;
  std::size_t cnt = 0;
  for (Eigen::Index i = 0; i < v.size(); ++i)
    if (rr.moving[ch.axis[static_cast<std::size_t>(i)]]) sum += v[i] * v[i], ++cnt;
  return cnt ? std::sqrt(sum / static_cast<double>(cnt)) : 0.0;
}

// The run with the sensor-side extensions of `taken` in its meta.
Run extended_run(const Run& run, const std::vector<ExplainedEffect>& taken) {
  const Extension ext = extend_sensors(run.meta, taken);
  Run extended = run;
  for (int s = 0; s < 2; ++s) extended.meta.sensors[s] = ext.sensors[s];
  extended.meta.acquisition.daq_group_delay_samples = ext.daq_group_delay_samples;
  extended.meta.acquisition.daq_skew_head_samples = ext.daq_skew_head_samples;
  return extended;
}

}  // namespace eical::dsp::model::stage
