#include "tools/report/tolerances.hpp"

#include "drivers/config/strict_toml.hpp"
#include "dsp/analysis/figures.hpp"

#include <cmath>
#include <limits>

namespace eical::tools::report {
namespace {

std::optional<double> tolerance(drivers::StrictTable& t, const char* key) {
  if (!t.has(key)) return std::nullopt;
  const double v = t.number(key);
  if (!(v > 0.0 && v < 1e6)) t.fail(key, "a tolerance must be positive (µm)");
  return v;
}

}  // namespace

Tolerances read_tolerances(const std::filesystem::path& file) {
  const toml::table doc = drivers::StrictTable::parse_file(file.string());
  drivers::StrictTable root(doc, file.string(), "");
  const std::string format = root.string("format");
  if (format != "eical-tolerances/1") root.fail("format", "expected \"eical-tolerances/1\", got \"" + format + "\"");
  Tolerances t;
  if (auto h = root.optional_table("header")) {
    t.machine = h->string("machine", "");
    t.serial = h->string("serial", "");
    t.operator_name = h->string("operator", "");
    h->finish();
  }
  if (auto c = root.optional_table("circle")) {
    t.G_um = tolerance(*c, "G_um");
    t.F_um = tolerance(*c, "F_um");
    c->finish();
  }
  if (auto p = root.optional_table("positioning")) {
    t.A_um = tolerance(*p, "A_um");
    t.B_um = tolerance(*p, "B_um");
    t.R_um = tolerance(*p, "R_um");
    t.E_um = tolerance(*p, "E_um");
    t.M_um = tolerance(*p, "M_um");
    p->finish();
  }
  root.finish();
  return t;
}

std::string decision(double value, std::optional<double> u, double tolerance) {
  const double uu = u && std::isfinite(*u) ? *u : std::numeric_limits<double>::infinity();
  if (value + uu <= tolerance) return "pass";
  if (value - uu > tolerance) return "fail";
  return "undecided";
}

std::vector<ToleranceDecision> decide(const dsp::Analysis& a, const Tolerances& t) {
  const auto figs = dsp::figures_of(a);
  std::vector<ToleranceDecision> out;
  auto get = [&](const char* key) -> std::optional<std::pair<double, std::optional<double>>> {
    const dsp::FigureValue* f = dsp::find_figure(figs, key);
    if (!f || f->values.empty() || !std::isfinite(f->values[0])) return std::nullopt;
    std::optional<double> u;
    const auto it = a.uncertainty_k2.find(key);
    if (it != a.uncertainty_k2.end() && !it->second.empty() && std::isfinite(it->second[0])) u = it->second[0];
    return std::make_pair(std::abs(f->values[0]), u);
  };
  auto add = [&](const char* name, const char* key, const std::optional<double>& tol) {
    if (!tol) return;
    if (const auto v = get(key)) out.push_back({name, v->first, v->second, *tol, decision(v->first, v->second, *tol)});
  };
  add("Circular deviation G (ISO 230-4)", "circle.circular_deviation_G_um", t.G_um);
  if (t.F_um) {  // the larger of |F max| and |F min|
    const auto fmax = get("circle.radial_deviation_F_max_um"), fmin = get("circle.radial_deviation_F_min_um");
    if (fmax && fmin) {
      const auto& f = fmax->first >= fmin->first ? *fmax : *fmin;
      out.push_back(
          {"Radial deviation F (ISO 230-4)", f.first, f.second, *t.F_um, decision(f.first, f.second, *t.F_um)});
    }
  }
  add("Accuracy A (ISO 230-2)", "positioning.A_um", t.A_um);
  add("Reversal value B (ISO 230-2)", "positioning.B_um", t.B_um);
  add("Repeatability R (ISO 230-2)", "positioning.R_um", t.R_um);
  add("Systematic deviation E (ISO 230-2)", "positioning.E_um", t.E_um);
  add("Mean positional deviation M (ISO 230-2)", "positioning.M_um", t.M_um);
  return out;
}

}  // namespace eical::tools::report
