#include "tools/comp/comp_inputs.hpp"

#include "drivers/results/result_json.hpp"
#include "drivers/run_io/run_reader.hpp"
#include "dsp/analysis/analyze_run.hpp"
#include "dsp/core/error.hpp"
#include "dsp/uncertainty/resolved.hpp"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

namespace eical::tools::comp {
namespace {

namespace fs = std::filesystem;

nlohmann::json read_json(const fs::path& file) {
  std::ifstream is(file);
  if (!is) throw dsp::InputError(file.string() + ": cannot open");
  try {
    return nlohmann::json::parse(is);
  } catch (const nlohmann::json::exception& e) {
    throw dsp::InputError(file.string() + ": not JSON: " + e.what());
  }
}

std::string num(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.3g", v);
  return b;
}

}  // namespace

CompInput load_comp_input(const std::string& path) {
  CompInput in;
  in.name = path;
  const fs::path p(path);
  if (fs::is_directory(p)) {
    if (!fs::exists(p / "run.toml")) throw dsp::InputError(path + ": a directory without run.toml is not an eical run");
    in.program = drivers::read_run_meta(p / "run.toml").program;
    if (fs::exists(p / "result.json")) {
      in.result = read_json(p / "result.json");
    } else {
      const dsp::Run run = drivers::read_run(p);
      in.result = drivers::result_json(run, dsp::analyze_run(run));
    }
  } else if (fs::is_regular_file(p)) {
    in.result = read_json(p);
  } else {
    throw dsp::InputError(path + ": no such run directory or result file");
  }
  if (!in.result.is_object() || in.result.value("format", std::string()) != "eical-result/1")
    throw dsp::InputError(path + ": not an eical-result/1 document (\"format\" must be \"eical-result/1\")");
  in.run_id = in.result.value("run_id", std::string());
  return in;
}

// The one rule of dsp/uncertainty/resolved.hpp (also the reports' and analyze's "not resolved").
bool Figure::resolved() const { return u_k2 && dsp::uncertainty::resolved(value, *u_k2); }

std::string Figure::describe() const {
  std::string s =
      key + " = " + num(value) + (u_k2 ? " (U = " + num(*u_k2) + ", k = 2)" : " (no uncertainty)") + " in " + input;
  return s;
}

nlohmann::json Figure::to_json() const {
  return {{"figure", key},
          {"input", input},
          {"value", value},
          {"U_k2", u_k2 ? nlohmann::json(*u_k2) : nlohmann::json(nullptr)},
          {"resolved", resolved()}};
}

Figure figure(const CompInput& in, const std::string& key) {
  const auto dot = key.find('.');
  const std::string section = key.substr(0, dot), name = key.substr(dot + 1);
  const auto& r = in.result;
  if (!r.contains(section) || !r[section].is_object() || !r[section].contains(name) || !r[section][name].is_number())
    throw dsp::InputError(in.name + ": " + key + " is missing or null (see the result's quality.flags)");
  Figure f;
  f.key = key;
  f.input = in.name;
  f.value = r[section][name].get<double>();
  if (r.contains("uncertainty_k2") && r["uncertainty_k2"].is_object() && r["uncertainty_k2"].contains(key) &&
      r["uncertainty_k2"][key].is_number())
    f.u_k2 = r["uncertainty_k2"][key].get<double>();
  return f;
}

Figure combined(const std::vector<Figure>& figures) {
  if (figures.size() == 1) return figures.front();
  Figure c = figures.front();
  double sum = 0.0, u2 = 0.0;
  bool all_u = true;
  c.input.clear();
  for (const auto& f : figures) {
    sum += f.value;
    if (f.u_k2)
      u2 += *f.u_k2 * *f.u_k2;
    else
      all_u = false;
    c.input += (c.input.empty() ? "" : " + ") + f.input;
  }
  const auto n = static_cast<double>(figures.size());
  c.value = sum / n;
  c.input = "mean of " + c.input;
  c.u_k2 = all_u ? std::optional<double>(std::sqrt(u2) / n) : std::nullopt;
  return c;
}

}  // namespace eical::tools::comp
