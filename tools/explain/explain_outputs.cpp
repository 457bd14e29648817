#include "tools/explain/explain_outputs.hpp"

#include "tools/explain/extended_model.hpp"
#include "tools/report/html.hpp"
#include "tools/report/svg.hpp"

#include <unsupported/Eigen/FFT>

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdio>
#include <map>

namespace eical::tools::explain {
namespace {

std::string report_fmt(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.3g", v);
  return b;
}

nlohmann::json effect_json(const dsp::model::ExplainedEffect& e) {
  nlohmann::json p = nlohmann::json::object();
  for (const auto& [k, v] : e.params) p[k] = std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr);
  return {{"name", e.name},
          {"significant", e.significant},
          {"taken_into_model", e.taken_into_model},
          {"evidence", e.evidence},
          {"params", p},
          {"channel", e.channel},
          {"identifiable", e.identifiable},
          {"size", e.identifiable ? nlohmann::json(e.magnitude) : nlohmann::json(nullptr)},
          {"tolerance", e.tolerance},
          {"unit", e.unit},
          {"bic_drop", e.bic_drop},
          {"residual_rms_before_um", e.residual_rms_before_um},
          {"residual_rms_after_um", e.residual_rms_after_um},
          {"heldout_rms_before_um", e.heldout_rms_before_um},
          {"heldout_rms_after_um", e.heldout_rms_after_um}};
}

}  // namespace

nlohmann::json explain_json(const std::vector<dsp::Run>& runs, const std::vector<dsp::model::RunExplanation>& ex,
                            const std::vector<dsp::model::TransferGain>& transfers) {
  nlohmann::json j;
  j["format"] = "eical-explain/1";
  j["runs"] = nlohmann::json::array();
  for (const auto& r : runs) j["runs"].push_back(r.meta.id);
  std::string reference = ex.empty() ? "cmd" : ex.front().reference;
  for (const auto& e : ex)
    if (e.reference != reference) reference = "mixed";
  j["reference"] = reference;
  // Over all runs: an effect is significant when it is in any run; its figures are from
  // the run where it explains most.
  std::vector<dsp::model::ExplainedEffect> merged;
  double before = 0.0, after = 0.0, hb = 0.0, ha = 0.0, seconds = 0.0;
  for (const auto& r : ex) {
    before += r.nominal_residual_rms_um * r.nominal_residual_rms_um,
        after += r.final_residual_rms_um * r.final_residual_rms_um;
    hb += r.heldout_nominal_rms_um * r.heldout_nominal_rms_um, ha += r.heldout_final_rms_um * r.heldout_final_rms_um;
    seconds += r.seconds;
    for (const auto& e : r.effects) {
      auto it = std::find_if(merged.begin(), merged.end(), [&](const auto& m) { return m.name == e.name; });
      if (it == merged.end())
        merged.push_back(e);
      else if ((e.significant && !it->significant) ||
               (e.significant == it->significant && e.importance_um > it->importance_um))
        *it = e;
    }
  }
  std::stable_sort(merged.begin(), merged.end(), [](const auto& a, const auto& b) {
    if (a.significant != b.significant) return a.significant;
    const bool ao = a.name.rfind("other.", 0) == 0, bo = b.name.rfind("other.", 0) == 0;
    if (a.significant && ao != bo) return bo;  // the table's effects first, as explain_run orders them
    return a.significant ? a.importance_um > b.importance_um : a.bic_drop > b.bic_drop;
  });
  const double n = std::max<double>(1.0, static_cast<double>(ex.size()));
  j["nominal_residual_rms_um"] = std::sqrt(before / n);
  j["effects"] = nlohmann::json::array();
  for (const auto& e : merged) j["effects"].push_back(effect_json(e));
  j["final_residual_rms_um"] = std::sqrt(after / n);
  j["heldout_nominal_residual_rms_um"] = std::sqrt(hb / n);
  j["heldout_final_residual_rms_um"] = std::sqrt(ha / n);
  j["runtime_s_per_run"] = seconds / n;
  j["per_run"] = nlohmann::json::array();
  for (const auto& r : ex) {
    nlohmann::json pr = {{"run_id", r.run_id},
                         {"reference", r.reference},
                         {"nominal_residual_rms_um", r.nominal_residual_rms_um},
                         {"final_residual_rms_um", r.final_residual_rms_um},
                         {"heldout_nominal_residual_rms_um", r.heldout_nominal_rms_um},
                         {"heldout_final_residual_rms_um", r.heldout_final_rms_um},
                         {"runtime_s", r.seconds}};
    if (!r.position_not_compared.empty()) pr["position_not_compared"] = r.position_not_compared;
    pr["correlations"] = nlohmann::json::array();
    for (const auto& c : r.correlations)
      pr["correlations"].push_back({{"axis", std::string(1, "xyz"[c.axis])}, {"regressor", c.regressor}, {"r", c.r}});
    pr["significant"] = nlohmann::json::array();
    for (const auto& e : r.effects)
      if (e.significant) pr["significant"].push_back(e.name);
    j["per_run"].push_back(pr);
  }
  // Held out across runs: each run's extension applied to the other runs.
  j["heldout_runs"] = nlohmann::json::array();
  for (const auto& t : transfers)
    j["heldout_runs"].push_back({{"model_from", t.from_run},
                                 {"applied_to", t.to_run},
                                 {"residual_rms_before_um", t.before_um},
                                 {"residual_rms_after_um", t.after_um}});
  return j;
}

std::string explain_text(const std::vector<dsp::model::RunExplanation>& ex,
                         const std::vector<dsp::model::TransferGain>& transfers) {
  std::string o;
  char b[512];
  for (const auto& r : ex) {
    if (!r.position_not_compared.empty())
      std::snprintf(b, sizeof b, "%s (compared with: %s): no position compared: %s; %.1f s\n", r.run_id.c_str(),
                    r.reference.c_str(), r.position_not_compared.c_str(), r.seconds);
    else
      std::snprintf(b, sizeof b,
                    "%s (compared with: %s): pipeline residual %.3f um RMS -> %.3f um with the extended model; model "
                    "prediction at held-out points %.3f -> %.3f um; %.1f s\n",
                    r.run_id.c_str(), r.reference.c_str(), r.nominal_residual_rms_um, r.final_residual_rms_um,
                    r.heldout_nominal_rms_um, r.heldout_final_rms_um, r.seconds);
    o += b;
    int sig = 0;
    for (const auto& e : r.effects) {
      if (!e.significant) continue;
      ++sig;
      std::snprintf(b, sizeof b, "  %d. %s  [%s]  %s\n", sig, e.name.c_str(), e.channel.c_str(), e.evidence.c_str());
      o += b;
    }
    if (sig == 0)
      o += "  no significant effect: the nominal model explains the run within its noise and the tolerance bands\n";
    std::string unsized;
    for (const auto& e : r.effects)
      if (!e.identifiable) unsized += (unsized.empty() ? "" : ", ") + e.name;
    if (!unsized.empty()) o += "  not identifiable (the run cannot size them; no size is given): " + unsized + "\n";
  }
  for (const auto& t : transfers) {
    std::snprintf(b, sizeof b, "held out: %s with the model extended on %s: pipeline residual %.3f -> %.3f um RMS\n",
                  t.to_run.c_str(), t.from_run.c_str(), t.before_um, t.after_um);
    o += b;
  }
  return o;
}

namespace {

using Explanation = dsp::model::RunExplanation;

// The effects, significant first.
report::Section effects_section(const Explanation& r) {
  report::Section table;
  table.heading = "Effects tested";
  table.lead =
      "each effect of the run format as a model extension: BIC with an effective sample count, a held-out guard, and "
      "the tolerance band";
  report::Grid g;
  g.header = {"", "effect", "size", "tolerance", "residual RMS before -> after (um)", "evidence"};
  for (const auto& e : r.effects)
    g.rows.push_back({e.significant ? "significant" : "", e.name,
                      e.identifiable ? report_fmt(e.magnitude) + " " + e.unit : "not identifiable",
                      report_fmt(e.tolerance),
                      report_fmt(e.residual_rms_before_um) + " -> " + report_fmt(e.residual_rms_after_um), e.evidence});
  table.grids.push_back(g);
  return table;
}

report::Section correlations_section(const Explanation& r) {
  report::Section cs;
  cs.heading = "Residual against the candidate regressors";
  cs.lead =
      "Pearson r of the nominal model's residual with each regressor, per moving axis (|r| near 1: the residual "
      "follows it)";
  report::Grid cg;
  cg.header = {"axis", "regressor", "r"};
  for (const auto& c : r.correlations) cg.rows.push_back({std::string(1, "xyz"[c.axis]), c.regressor, report_fmt(c.r)});
  cs.grids.push_back(cg);
  return cs;
}

// Amplitude spectrum of a series' first power-of-two samples (the samples are at ~1 kHz,
// not exactly uniform where thinned).
report::LineSeries amplitude_spectrum(const report::LineSeries& in_time, std::size_t nfft, double dt,
                                      Eigen::FFT<double>& fft) {
  report::LineSeries sp;
  sp.label = in_time.label, sp.color = in_time.color;
  std::vector<double> in(in_time.y.begin(), in_time.y.begin() + static_cast<std::ptrdiff_t>(nfft));
  std::vector<std::complex<double>> out;
  fft.fwd(out, in);
  for (std::size_t f = 1; f < nfft / 2; ++f) {
    sp.x.push_back(static_cast<double>(f) / (static_cast<double>(nfft) * dt));
    sp.y.push_back(2.0 * std::abs(out[f]) / static_cast<double>(nfft));
  }
  return sp;
}

// One axis of one channel: the residual before and after in time and in frequency (none
// for fewer than 16 samples).
void residual_plots(const Explanation::Trace& tr, int a, report::Section& s) {
  const char* axes[3] = {"x", "y", "z"};
  report::LineSeries before, after;
  before.label = "nominal model", before.color = report::kRed;
  after.label = "with the significant effects", after.color = report::kBlue;
  for (std::size_t k = 0; k < tr.t_s.size(); ++k) {
    if (tr.axis[k] != a) continue;
    before.x.push_back(tr.t_s[k]), before.y.push_back(tr.before_um[k]);
    after.x.push_back(tr.t_s[k]), after.y.push_back(tr.after_um[k]);
  }
  if (before.x.size() < 16) return;
  s.svgs.push_back(
      report::line_plot({before, after}, std::string(axes[a]) + ": residual in time", "time (s)", "residual (um)"));
  const std::size_t m = before.y.size();
  std::size_t nfft = 1;
  while (nfft * 2 <= m) nfft *= 2;
  const double dt = (before.x[nfft - 1] - before.x[0]) / static_cast<double>(nfft - 1);
  Eigen::FFT<double> fft;
  const report::LineSeries sb = amplitude_spectrum(before, nfft, dt, fft);
  const report::LineSeries sa = amplitude_spectrum(after, nfft, dt, fft);
  s.svgs.push_back(report::line_plot({sb, sa}, std::string(axes[a]) + ": residual amplitude spectrum", "frequency (Hz)",
                                     "amplitude (um)"));
}

// Residuals before and after, per channel and axis, in time and frequency.
report::Section residual_section(const Explanation::Trace& tr) {
  report::Section s;
  s.heading = "Residual, " + tr.channel;
  s.lead = tr.channel == "ref" ? "the pipeline's path minus the reference instrument, each axis' offset out"
           : tr.channel == "psd"
               ? "the pipeline's path minus the PSD readings, each axis' offset out"
               : "the pipeline's path minus the set-point (sensor and machine together), each axis' offset out";
  for (int a = 0; a < 3; ++a) residual_plots(tr, a, s);
  return s;
}

report::Section extended_model_section(const ExtendedModel& model) {
  report::Section ext;
  ext.heading = "The extended model";
  ext.lead =
      "the significant sensor effects as a sensor calibration, the machine effects as a scenario the simulator "
      "reproduces the run with";
  ext.notes = model.notes;
  return ext;
}

// One run's page and the extended model's two files beside it.
void write_run_report(const dsp::Run& run, const Explanation& r, const std::filesystem::path& dir) {
  report::Page page;
  page.title = "What the simulation gets wrong";
  page.run_id = r.run_id;
  page.program = dsp::program_kind_name(run.meta.program.kind);
  page.context = {{"compared with", r.reference},
                  {"pipeline residual RMS, extended model",
                   report_fmt(r.nominal_residual_rms_um) + " -> " + report_fmt(r.final_residual_rms_um) + " um"},
                  {"prediction at held-out reference points",
                   report_fmt(r.heldout_nominal_rms_um) + " -> " + report_fmt(r.heldout_final_rms_um) + " um"}};
  page.sections.push_back(effects_section(r));
  if (!r.correlations.empty()) page.sections.push_back(correlations_section(r));
  for (const auto& tr : r.traces) page.sections.push_back(residual_section(tr));
  const auto model = extended_model(run, r);
  page.files.push_back(r.run_id + "-calibration.toml");
  page.files.push_back(r.run_id + "-scenario.toml");
  page.sections.push_back(extended_model_section(model));
  report::write_html(page, dir / (r.run_id + ".html"));
  write_extended_model(model, dir / (r.run_id + "-calibration.toml"), dir / (r.run_id + "-scenario.toml"));
}

}  // namespace

void write_explain_report(const std::vector<dsp::Run>& runs, const std::vector<dsp::model::RunExplanation>& ex,
                          const std::filesystem::path& dir) {
  std::filesystem::create_directories(dir);
  for (std::size_t i = 0; i < runs.size() && i < ex.size(); ++i) write_run_report(runs[i], ex[i], dir);
}

}  // namespace eical::tools::explain
