#include "dsp/eval/circle_diagnostics.hpp"
#include "dsp/core/error.hpp"
#include "dsp/eval/circle_fit.hpp"

#include <algorithm>
#include <array>
#include <cmath>

namespace eical::dsp::eval {
namespace diagnostics_fit {
namespace {

// First replay: the normal equations of both axes over every pitch, outside the reversal
// windows; records each axis' first direction of motion per pass into its model.
std::vector<AxisGram> accumulate_every_pitch(PassReplay& replay, std::size_t window, std::array<AxisModel, 2>& model) {
  const std::size_t n_pitch = model[0].pitches_mm.size();
  std::vector<AxisGram> gram;
  for (int a = 0; a < 2; ++a) gram.emplace_back(replay.passes().size(), n_pitch);
  std::vector<double> cyc(2 * n_pitch);
  walk(replay, window, [&model, &gram, &cyc](const Walked& w) {
    for (int a = 0; a < 2; ++a) {
      if (model[a].d0[w.pass] == 0) model[a].d0[w.pass] = sgn(w.vel[a], 1e-6);
      if (w.skip[a]) continue;
      double c9[9], target = 0.0;
      model[a].row(w, c9, cyc.data(), target);
      gram[a].add_row(w.pass, c9, target, cyc.data(), cyc.size());
    }
  });
  for (auto& g : gram) g.flush();
  return gram;
}

// Second replay: the normal equations of both axes for the one pitch the models hold now.
std::vector<AxisGram> accumulate_best_pitch(PassReplay& replay, std::size_t window, std::array<AxisModel, 2>& model) {
  std::vector<AxisGram> gram;
  for (int a = 0; a < 2; ++a) gram.emplace_back(replay.passes().size(), 1);
  walk(replay, window, [&model, &gram](const Walked& w) {
    for (int a = 0; a < 2; ++a) {
      double c9[9], cyc[2], target = 0.0;
      model[a].row(w, c9, cyc, target);  // every sample: the play operator runs through the skipped ones too
      if (w.skip[a]) continue;
      gram[a].add_row(w.pass, c9, target, cyc, 2);
    }
  });
  for (auto& g : gram) g.flush();
  return gram;
}

}  // namespace
}  // namespace diagnostics_fit

CircleDiagnostics diagnose_circle(const std::vector<CirclePass>& passes, const DiagnosticsOptions& options) {
  using namespace diagnostics_fit;
  for (const auto& p : passes)
    if (p.cmd_mm.size() != p.meas_mm.size())
      throw InputError("circle diagnostics: commanded and measured traces differ in length");
  StoredPasses replay(passes);
  return diagnose_circle(replay, options);
}

CircleDiagnostics diagnose_circle(PassReplay& replay, const DiagnosticsOptions& opt) {
  using namespace diagnostics_fit;
  const auto& passes = replay.passes();
  const bool both_directions = check_passes(passes, opt);
  const auto window = static_cast<std::size_t>(std::lround(opt.spike_window_s * passes.front().fs_hz));
  const std::vector<double> pitches = candidate_pitches(opt);
  DecimatedPasses fit_replay(replay,
                             static_cast<std::size_t>(std::max(1.0, std::floor(passes.front().fs_hz / kFitRateHz))));
  const auto fit_window = static_cast<std::size_t>(std::lround(opt.spike_window_s * fit_replay.passes().front().fs_hz));

  // First replay: every pitch with the backlash as a step, both axes; each axis' first
  // direction of motion per pass (the play operator starts from it).
  std::array<AxisModel, 2> model = step_models(opt, pitches, passes.size());
  const std::vector<AxisGram> gram = accumulate_every_pitch(fit_replay, fit_window, model);
  const std::size_t best = search_pitch(gram, pitches.size());
  // Round one: the backlash as a step (what the pitch search fitted).
  const AxisFits round_one = fit_axes(gram, best, both_directions);

  // Second replay, round two: the play operator of the play just found (a sharp step
  // would leave the play's crossing time as a false reversal spike).
  for (std::size_t a = 0; a < 2; ++a) {
    model[a].set_pitches({pitches[best]});
    model[a].play_mm = std::max(0.0, round_one.axis[a].coef(backlash));
  }
  const AxisFits fits = fit_axes(accumulate_best_pitch(fit_replay, fit_window, model), 0, both_directions);

  CircleDiagnostics d;
  report_fit(fits, pitches[best], both_directions, d);
  // Third replay: the residuals of the final fits.
  ResidualMeter meter(model, fits, opt.centre_mm, window);
  walk(replay, window, [&meter](const Walked& w) { meter.add(w); });
  report_residuals(meter.sums(), opt, d);
  return d;
}

std::vector<Flag> null_reasons(const CircleDiagnostics& d, const DiagnosticsOptions& options) {
  std::vector<Flag> out;
  auto null = [&out](const char* key, std::string why) { out.push_back({FlagCode::figure_null, key, std::move(why)}); };
  if (!d.servo_and_squareness_separated)
    null("diagnostics.servo_mismatch_ms",
         "one direction cannot separate servo mismatch from squareness (squareness assumes equal lags)");
  const std::string creep = std::to_string(static_cast<long>(options.creep_feed_mm_min)) + " mm/min";
  if (std::isnan(d.stick_slip_um))
    null("diagnostics.stick_slip_um",
         "not evaluated above the creep feed (" + creep + "): the fast residual there is vibration");
  if (std::isnan(d.vibration_um))
    null("diagnostics.vibration_um",
         "not evaluated at creep feed (at most " + creep + "): the fast residual there is stick-slip");
  if (std::isnan(d.reversal_spike_x_um))
    null("diagnostics.reversal_spike_x_um", "the first axis never reverses in this test");
  if (std::isnan(d.reversal_spike_y_um))
    null("diagnostics.reversal_spike_y_um", "the second axis never reverses in this test");
  return out;
}

}  // namespace eical::dsp::eval
