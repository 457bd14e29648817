#include "tools/io/volumetric_model_file.hpp"

#include "drivers/config/strict_toml.hpp"
#include "dsp/core/error.hpp"

#include <array>
#include <cstdio>

namespace eical::tools {
namespace {

using dsp::comp::kVolumetricComponents;

std::string numbers(const std::vector<double>& v, const char* fmt = "%.6g") {
  std::string s = "[";
  for (std::size_t i = 0; i < v.size(); ++i) {
    char b[32];
    std::snprintf(b, sizeof b, fmt, v[i]);
    s += (i ? ", " : "") + std::string(b);
  }
  return s + "]";
}

std::string toml_string(const std::string& s) {
  std::string o = "\"";
  for (char c : s) o += c == '"' ? std::string("\\\"") : c == '\\' ? std::string("\\\\") : std::string(1, c);
  return o + "\"";
}

}  // namespace

dsp::comp::VolumetricFit read_volumetric_model(const std::string& file) {
  const toml::table root = drivers::StrictTable::parse_file(file);
  drivers::StrictTable t(root, file, "");
  const std::string format = t.string("format");
  if (format != "eical-volumetric/1") t.fail("format", "expected \"eical-volumetric/1\", got \"" + format + "\"");
  dsp::comp::VolumetricFit f;
  dsp::comp::VolumetricModel& m = f.model;
  auto axes = t.table("axes");
  const char* keys[3] = {"x_range_mm", "y_range_mm", "z_range_mm"};
  for (int a = 0; a < 3; ++a) {
    const auto r = axes.numbers(keys[a], 2);
    m.range_mm[a] = {r[0], r[1]};
  }
  axes.finish();
  auto sq = t.table("squareness");
  m.xwy_urad = sq.number("xwy");
  m.xwz_urad = sq.number("xwz");
  m.ywz_urad = sq.number("ywz");
  const char* sq_u[3] = {"xwy_u_k2", "ywz_u_k2", "xwz_u_k2"};  // a fitted model's uncertainties
  for (int s = 0; s < 3; ++s)
    if (sq.has(sq_u[s])) f.squareness[s].observed = true, f.squareness[s].u_k2_urad = sq.number(sq_u[s]);
  sq.finish();
  std::array<bool, 18> seen{};
  for (auto& c : t.tables("component")) {
    const std::string name = c.string("name");
    int k = -1;
    for (int i = 0; i < 18; ++i)
      if (name == kVolumetricComponents[i]) k = i;
    if (k < 0) c.fail("name", "'" + name + "' is not one of xtx, xty, ..., zrz");
    if (seen[k]) c.fail("name", "component '" + name + "' appears twice");
    seen[k] = true;
    m.component[k].pos_mm = c.numbers("positions_mm");
    m.component[k].values = c.numbers("values", m.component[k].pos_mm.size());
    auto& fit = f.component[k];
    if (c.has("u_k2")) {
      fit.u_k2 = c.numbers("u_k2", m.component[k].pos_mm.size());
      fit.observed = true;
    }
    if (!c.boolean("observed", true)) fit.observed = false, fit.u_k2.clear();
    fit.note = c.string("note", "");
    c.finish();
  }
  t.finish();
  try {
    dsp::comp::validate(m);  // missing components, order, coverage
  } catch (const dsp::InputError& e) {
    throw dsp::InputError(file + ": " + e.what());
  }
  return f;
}

std::string volumetric_model_toml(const dsp::comp::VolumetricFit& fit, const std::vector<std::string>& runs) {
  const auto& m = fit.model;
  std::string t = "# eical-volumetric/1 fitted by eical volumetric --fit from:\n";
  for (const auto& r : runs) t += "#   " + r + "\n";
  t += "# Translations (t) in um, rotations (r) and squareness (w) in urad, positions in mm; u_k2 the expanded\n"
       "# uncertainty (k = 2) of each value. Values are relative to the machine at the origin of the measured range.\n"
       "format = \"eical-volumetric/1\"\n\n[axes]\n";
  const char* keys[3] = {"x_range_mm", "y_range_mm", "z_range_mm"};
  for (int a = 0; a < 3; ++a) t += std::string(keys[a]) + " = " + numbers({m.range_mm[a][0], m.range_mm[a][1]}) + "\n";
  t += "\n[squareness]\n";
  const char* names[3] = {"xwy", "ywz", "xwz"};
  const double values[3] = {m.xwy_urad, m.ywz_urad, m.xwz_urad};
  for (int s = 0; s < 3; ++s) {
    char b[160];
    std::snprintf(b, sizeof b, "%s = %.4g  # %s\n", names[s], values[s], fit.squareness[s].note.c_str());
    t += b;
    if (fit.squareness[s].observed) {
      std::snprintf(b, sizeof b, "%s_u_k2 = %.4g\n", names[s], fit.squareness[s].u_k2_urad);
      t += b;
    }
  }
  for (int k = 0; k < 18; ++k) {
    const auto& c = fit.component[k];
    t += "\n[[component]]\nname = \"" + std::string(kVolumetricComponents[k]) + "\"\n";
    t += "positions_mm = " + numbers(m.component[k].pos_mm) + "\nvalues = " + numbers(m.component[k].values, "%.4f") +
         "\n";
    if (c.observed)
      t += "u_k2 = " + numbers(c.u_k2, "%.4f") + "\n";
    else
      t += "observed = false\n";
    t += "note = " + toml_string(c.note) + "\n";
  }
  return t;
}

}  // namespace eical::tools
