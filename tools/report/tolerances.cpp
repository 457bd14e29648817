#include "tools/report/tolerances.hpp"

#include "drivers/config/strict_toml.hpp"

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

std::vector<dsp::FigureTolerance> figure_tolerances(const Tolerances& t) {
  std::vector<dsp::FigureTolerance> out;
  auto add = [&](const char* name, std::vector<std::string> keys, const std::optional<double>& tol) {
    if (tol) out.push_back({name, std::move(keys), *tol});
  };
  add("circular deviation G (ISO 230-4)", {"circle.circular_deviation_G_um"}, t.G_um);
  add("radial deviation F (ISO 230-4)", {"circle.radial_deviation_F_max_um", "circle.radial_deviation_F_min_um"},
      t.F_um);
  add("accuracy A (ISO 230-2)", {"positioning.A_um"}, t.A_um);
  add("reversal value B (ISO 230-2)", {"positioning.B_um"}, t.B_um);
  add("repeatability R (ISO 230-2)", {"positioning.R_um"}, t.R_um);
  add("systematic deviation E (ISO 230-2)", {"positioning.E_um"}, t.E_um);
  add("mean positional deviation M (ISO 230-2)", {"positioning.M_um"}, t.M_um);
  return out;
}

}  // namespace eical::tools::report
