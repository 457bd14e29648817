#include "tools/io/positioning_readers.hpp"

#include "dsp/core/error.hpp"
#include "tools/io/csv_table.hpp"

#include <charconv>
#include <cmath>
#include <fstream>
#include <map>
#include <tuple>

namespace eical::tools {
namespace {

// What ISO 230-2 needs of a table (evaluate_positioning checks it again, without a file
// to name).
void require_table(const std::string& file, std::size_t targets, long long runs, const char* what) {
  if (targets < 2)
    throw dsp::InputError(file + ": at least 2 targets are needed for ISO 230-2 (the file has " +
                          std::to_string(targets) + ")");
  if (runs < 2)
    throw dsp::InputError(file + ": at least 2 " + what + " per direction are needed for ISO 230-2 (the file has " +
                          std::to_string(runs) + ")");
}

}  // namespace

dsp::eval::PositioningInput read_deviation_csv(const std::string& file) {
  const CsvTable t(file, {"target_mm", "run", "direction", "deviation_um"});
  std::map<long long, double> target_of;  // key: target in nm
  std::map<std::tuple<long long, long long, int>, double> value;
  long long max_run = 0;
  for (std::size_t r = 0; r < t.rows(); ++r) {
    const double target = t.number(r, "target_mm");
    const long long run = t.integer(r, "run");
    if (run < 1) throw dsp::InputError(t.where(r, "run") + ": runs are numbered from 1");
    const std::string& d = t.text(r, "direction");
    if (d != "up" && d != "down")
      throw dsp::InputError(t.where(r, "direction") + ": expected up or down, got '" + d + "'");
    const double dev = t.number(r, "deviation_um");
    const long long key = std::llround(target * 1e6);
    target_of[key] = target;
    if (!value.emplace(std::tuple{key, run, d == "up" ? 0 : 1}, dev).second)
      throw dsp::InputError(t.where(r, "run") + ": target " + std::to_string(target) + " mm, run " +
                            std::to_string(run) + ", " + d + " appears twice");
    max_run = std::max(max_run, run);
  }
  require_table(file, target_of.size(), max_run, "runs");
  dsp::eval::PositioningInput in;
  for (const auto& [k, v] : target_of) in.targets_mm.push_back(v);
  // A run is added only when it is complete: a run number far beyond the rows (run
  // 1000000000000) ends at the first missing run, never in an allocation of that size.
  for (long long run = 1; run <= max_run; ++run) {
    in.up_um.emplace_back(), in.down_um.emplace_back();
    for (const auto& [k, v] : target_of)
      for (int dir = 0; dir < 2; ++dir) {
        const auto it = value.find({k, run, dir});
        if (it == value.end())
          throw dsp::InputError(file + ": no deviation for target " + std::to_string(v) + " mm, run " +
                                std::to_string(run) + ", " + (dir ? "down" : "up"));
        (dir ? in.down_um : in.up_um).back().push_back(it->second);
      }
  }
  return in;
}

dsp::eval::PositioningInput read_ecmc_dat(const std::string& file) {
  std::ifstream is(file);
  if (!is) throw dsp::InputError(file + ": cannot open");
  std::map<int, double> targets;
  std::map<std::tuple<int, int, int>, double> refs;  // (dir, target, cycle)
  std::string line;
  int no = 0;
  auto number = [&](const std::string& s) {
    double v = 0.0;
    const auto [p, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
    if (ec != std::errc() || p != s.data() + s.size() || !std::isfinite(v))
      throw dsp::InputError(file + ":" + std::to_string(no) + ": '" + s + "' is not a number");
    return v;
  };
  while (std::getline(is, line)) {
    ++no;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.find_first_not_of(" \t") == std::string::npos || line[0] == '#') continue;
    // NAME[i] = value or NAME[i,j] = value (no regex: plain parsing keeps it strict and fast).
    std::string t;
    for (char ch : line)
      if (ch != ' ' && ch != '\t') t += ch;
    const auto open = t.find('['), close = t.find(']'), eq = t.find('=');
    if (open == std::string::npos || close == std::string::npos || eq == std::string::npos ||
        !(open < close && close < eq))
      throw dsp::InputError(file + ":" + std::to_string(no) + ": not a TGT_DATA or REF_DATA line: '" + line + "'");
    const std::string name = t.substr(0, open), index = t.substr(open + 1, close - open - 1), value = t.substr(eq + 1);
    auto int_of = [&](const std::string& s) {
      int v = 0;
      const auto [p, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
      if (s.empty() || ec != std::errc() || p != s.data() + s.size() || v < 1)
        throw dsp::InputError(file + ":" + std::to_string(no) + ": index '" + s + "' is not a positive integer");
      return v;
    };
    if (name == "TGT_DATA") {
      targets[int_of(index)] = number(value);
    } else if (name == "REF_DATA_FWD" || name == "REF_DATA_BWD") {
      const auto comma = index.find(',');
      if (comma == std::string::npos)
        throw dsp::InputError(file + ":" + std::to_string(no) + ": " + name + " needs [target,cycle]");
      refs[{name == "REF_DATA_FWD" ? 0 : 1, int_of(index.substr(0, comma)), int_of(index.substr(comma + 1))}] =
          number(value);
    } else {
      throw dsp::InputError(file + ":" + std::to_string(no) + ": unknown name '" + name +
                            "' (TGT_DATA, REF_DATA_FWD, REF_DATA_BWD)");
    }
  }
  if (targets.empty()) throw dsp::InputError(file + ": no TGT_DATA lines");
  int cycles = 0;
  for (const auto& [k, v] : refs) cycles = std::max(cycles, std::get<2>(k));
  require_table(file, targets.size(), cycles, "cycles");
  dsp::eval::PositioningInput in;
  for (const auto& [i, t] : targets) in.targets_mm.push_back(t);
  for (int j = 1; j <= cycles; ++j) {  // a cycle is added when complete (as the deviation CSV's runs)
    in.up_um.emplace_back(), in.down_um.emplace_back();
    for (const auto& [i, t] : targets)
      for (int dir = 0; dir < 2; ++dir) {
        const auto it = refs.find({dir, i, j});
        if (it == refs.end())
          throw dsp::InputError(file + ": REF_DATA_" + (dir ? "BWD" : "FWD") + "[" + std::to_string(i) + "," +
                                std::to_string(j) + "] is missing");
        (dir ? in.down_um : in.up_um).back().push_back((it->second - t) * 1000.0);  // REF − TGT, µm
      }
  }
  return in;
}

}  // namespace eical::tools
