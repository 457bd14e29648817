#include "dsp/eval/step_response.hpp"
#include "dsp/core/units.hpp"

#include "dsp/core/error.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <utility>

namespace eical::dsp::eval {
namespace {

using units::kUmPerMm;
constexpr double kRestTolMm = 1e-9;  // the set-point is exact: "not moving" means unchanged

double mean(const std::vector<double>& v, std::size_t a, std::size_t b) {
  return std::accumulate(v.begin() + static_cast<std::ptrdiff_t>(a), v.begin() + static_cast<std::ptrdiff_t>(b), 0.0) /
         static_cast<double>(b - a);
}

using Interval = std::pair<std::size_t, std::size_t>;  // [begin, end)

void check_inputs(const std::vector<double>& cmd, const std::vector<double>& meas, double fs_hz) {
  if (cmd.size() != meas.size()) throw InputError("step evaluation: command and measurement differ in length");
  if (!(fs_hz > 0.0)) throw InputError("step evaluation: fs_hz must be positive");
  for (std::size_t i = 0; i < cmd.size(); ++i)
    if (!std::isfinite(cmd[i]) || !std::isfinite(meas[i]))
      throw InputError("step evaluation: non-finite position at sample " + std::to_string(i));
}

// Rest intervals of the set-point: [begin, end) with cmd constant and at least min_dwell long.
std::vector<Interval> rests_of(const std::vector<double>& cmd, std::size_t min_dwell) {
  const auto n = cmd.size();
  std::vector<Interval> rests;
  std::size_t i = 0;
  while (i < n) {
    std::size_t j = i + 1;
    while (j < n && std::abs(cmd[j] - cmd[i]) <= kRestTolMm) ++j;
    if (j - i >= min_dwell) rests.emplace_back(i, j);
    i = j;
  }
  return rests;
}

// The move between two rests: the measured step and end error from the mean over the last
// end_win samples of each rest, the overshoot, the settling; `dwell_noise_um`: the RMS about
// that mean at the end of the arrival rest.
StepMove measure_move(const std::vector<double>& cmd, const std::vector<double>& meas, const Interval& from,
                      const Interval& to, std::size_t end_win, double fs_hz, const StepOptions& opt,
                      double& dwell_noise_um) {
  const auto [b0, e0] = from;
  const auto [b1, e1] = to;
  StepMove m;
  m.start = e0;
  m.arrive = b1;
  m.end = e1;
  m.from_mm = cmd[b0];
  m.to_mm = cmd[b1];
  const double dir = m.to_mm > m.from_mm ? 1.0 : -1.0;
  const std::size_t w0 = std::min(end_win, e0 - b0), w1 = std::min(end_win, e1 - b1);
  const double before = mean(meas, e0 - w0, e0);
  const double after = mean(meas, e1 - w1, e1);
  m.step_measured_um = (after - before) * kUmPerMm;
  m.end_error_um = (after - m.to_mm) * kUmPerMm;
  double over = 0.0;
  for (std::size_t s = m.start; s < m.end; ++s) over = std::max(over, (meas[s] - m.to_mm) * dir);
  m.overshoot_um = over * kUmPerMm;
  // Settling: last sample outside the band (about the final value, so that a constant
  // end error is not mistaken for "never settles").
  std::size_t last_out = m.arrive;
  bool any_out = false;
  for (std::size_t s = m.arrive; s < m.end; ++s)
    if (std::abs(meas[s] - after) * kUmPerMm > opt.settle_band_um) last_out = s, any_out = true;
  m.settled = !any_out || last_out + w1 < m.end;
  m.settling_s = any_out ? static_cast<double>(last_out + 1 - m.arrive) / fs_hz : 0.0;
  double ss = 0.0;
  for (std::size_t s = e1 - w1; s < e1; ++s) ss += (meas[s] - after) * (meas[s] - after);
  dwell_noise_um = std::sqrt(ss / static_cast<double>(w1)) * kUmPerMm;
  return m;
}

// Pooled standard deviation over groups with repeats (n − 1 per group).
double pooled_scatter(const std::map<std::pair<long long, int>, std::vector<double>>& groups) {
  double ss = 0.0;
  std::size_t dof = 0;
  for (const auto& [key, errs] : groups) {
    if (errs.size() < 2) continue;
    const double mu = std::accumulate(errs.begin(), errs.end(), 0.0) / static_cast<double>(errs.size());
    for (double e : errs) ss += (e - mu) * (e - mu);
    dof += errs.size() - 1;
  }
  return dof > 0 ? std::sqrt(ss / static_cast<double>(dof)) : 0.0;
}

// Each move resolved or not (against r.noise_um); the moves' mean end error, worst
// overshoot, longest settling and the scatter of the end errors per target and direction.
void summarise_moves(StepResult& r) {
  std::map<std::pair<long long, int>, std::vector<double>> groups;  // (target nm, direction) → end errors
  double sum_err = 0.0;
  for (auto& m : r.moves) {
    const double cmd_step_um = (m.to_mm - m.from_mm) * kUmPerMm;
    m.resolved = std::abs(m.step_measured_um - cmd_step_um) < 0.5 * std::abs(cmd_step_um) &&
                 std::abs(m.step_measured_um) > 3.0 * r.noise_um;
    sum_err += m.end_error_um;
    r.overshoot_um = std::max(r.overshoot_um, m.overshoot_um);
    if (m.settled) r.settling_s = std::max(r.settling_s, m.settling_s);
    groups[{std::llround(m.to_mm * 1e6), m.to_mm > m.from_mm ? 1 : -1}].push_back(m.end_error_um);
  }
  r.end_position_error_um = sum_err / static_cast<double>(r.moves.size());
  r.scatter_um = pooled_scatter(groups);
}

// Smallest step resolved: sort moves by commanded size; walk down while resolved (0: none).
double smallest_step_resolved_um(const std::vector<StepMove>& moves) {
  std::vector<const StepMove*> by_size;
  for (const auto& m : moves) by_size.push_back(&m);
  std::sort(by_size.begin(), by_size.end(), [](const StepMove* a, const StepMove* b) {
    return std::abs(a->to_mm - a->from_mm) > std::abs(b->to_mm - b->from_mm);
  });
  double smallest = 0.0;
  for (const StepMove* m : by_size) {
    if (!m->resolved) break;
    smallest = std::abs(m->to_mm - m->from_mm) * kUmPerMm;
  }
  return smallest;
}

}  // namespace

StepResult evaluate_steps(const std::vector<double>& cmd_mm, const std::vector<double>& meas_mm, double fs_hz,
                          const StepOptions& options) {
  check_inputs(cmd_mm, meas_mm, fs_hz);
  const auto min_dwell = static_cast<std::size_t>(std::lround(options.min_dwell_s * fs_hz));
  const auto end_win = std::max<std::size_t>(1, static_cast<std::size_t>(std::lround(options.end_window_s * fs_hz)));
  const std::vector<Interval> rests = rests_of(cmd_mm, min_dwell);
  StepResult r;
  std::vector<double> dwell_noise(rests.empty() ? 0 : rests.size() - 1);
  for (std::size_t k = 0; k + 1 < rests.size(); ++k)
    r.moves.push_back(measure_move(cmd_mm, meas_mm, rests[k], rests[k + 1], end_win, fs_hz, options, dwell_noise[k]));
  if (r.moves.empty()) throw InputError("step evaluation: no complete move (rest, move, rest) in the command trace");
  std::sort(dwell_noise.begin(), dwell_noise.end());
  r.noise_um = dwell_noise[dwell_noise.size() / 2];  // median: robust to one badly settled dwell
  summarise_moves(r);
  r.smallest_step_resolved_um = smallest_step_resolved_um(r.moves);
  return r;
}

}  // namespace eical::dsp::eval
