// Golden outputs (issue 20, item 4): `eical analyze --json --no-suggest` and `eical explain --json` of every
// sample run (tests/data, and EICAL_EXTRA_DATA when present) diffed against tests/golden/expected with the per-key
// tolerances of tests/golden/tolerances.toml. A failure lists every changed key, old → new. EICAL_GOLDEN_UPDATE=1
// rewrites the expected documents instead (read the diff, commit both).
#include "dsp/core/float_limits.hpp"
#include "tests/support/sample_data.hpp"

#include <gtest/gtest.h>
#include <toml++/toml.h>
#include <nlohmann/json.hpp>

#include <sys/wait.h>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <ostream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;

const fs::path kExpected = fs::path(EICAL_SOURCE_DIR) / "tests/golden/expected";
const fs::path kTolerances = fs::path(EICAL_SOURCE_DIR) / "tests/golden/tolerances.toml";
constexpr std::size_t kSummariseAbove = 32;  // numeric arrays longer than this: n, min, max, rms

struct Case {
  std::string command;  // analyze | explain
  fs::path run;
  std::string name;  // the run directory's name
};

// ctest's test list shows the command and the run, not the parameter's bytes.
void PrintTo(const Case& c, std::ostream* os) { *os << c.command << " " << c.name; }

std::vector<Case> cases() {
  std::vector<Case> out;
  // None when tests/data is missing: GoogleTest then fails the uninstantiated suite, and
  // GoldenData.CommittedRunsPresent says why.
  std::vector<fs::path> runs = eical::test::runs_in(eical::test::committed_data(), true);
  const auto more = eical::test::extra_runs();
  runs.insert(runs.end(), more.begin(), more.end());
  for (const char* cmd : {"analyze", "explain"})
    for (const auto& r : runs) out.push_back({cmd, r, r.filename().string()});
  return out;
}

struct Tolerance {
  double rel = 0.0, abs = 0.0;
};

struct Tolerances {
  Tolerance fallback;
  std::vector<std::pair<std::string, Tolerance>> rules;
  std::set<std::string> ignore;

  [[nodiscard]] Tolerance at(const std::string& path) const {
    for (const auto& [key, t] : rules)
      if (path.find(key) != std::string::npos) return t;
    return fallback;
  }
};

Tolerances read_tolerances() {
  const toml::table t = toml::parse_file(kTolerances.string());
  Tolerances out;
  auto one = [](const toml::table& x) { return Tolerance{x["rel"].value_or(0.0), x["abs"].value_or(0.0)}; };
  if (const auto* d = t["default"].as_table()) out.fallback = one(*d);
  if (const auto* rules = t["rule"].as_array())
    for (const auto& r : *rules)
      if (const auto* rt = r.as_table()) out.rules.emplace_back((*rt)["key"].value_or(std::string()), one(*rt));
  if (const auto* keys = t["ignore"]["keys"].as_array())
    for (const auto& k : *keys) out.ignore.insert(k.value_or(std::string()));
  return out;
}

// Timings and the version out; long numeric arrays as their summary.
json canonical(const json& j, const Tolerances& tol) {
  if (j.is_object()) {
    json o = json::object();
    for (const auto& [k, v] : j.items())
      if (!tol.ignore.count(k)) o[k] = canonical(v, tol);
    return o;
  }
  if (j.is_array()) {
    bool numeric = j.size() > kSummariseAbove;
    for (const auto& v : j) numeric = numeric && (v.is_number() || v.is_null());
    if (numeric) {
      double lo = eical::kInf, hi = -eical::kInf, ss = 0.0;
      std::size_t n = 0, nulls = 0;
      for (const auto& v : j) {
        if (v.is_null()) {
          ++nulls;
          continue;
        }
        const double x = v.get<double>();
        lo = std::min(lo, x), hi = std::max(hi, x), ss += x * x, ++n;
      }
      return json{{"summary_n", j.size()},
                  {"summary_nulls", nulls},
                  {"summary_min", n ? json(lo) : json()},
                  {"summary_max", n ? json(hi) : json()},
                  {"summary_rms", n ? json(std::sqrt(ss / static_cast<double>(n))) : json()}};
    }
    json a = json::array();
    for (const auto& v : j) a.push_back(canonical(v, tol));
    return a;
  }
  return j;
}

std::string shown(const json& j) {
  std::string s = j.dump();
  return s.size() > 120 ? s.substr(0, 117) + "..." : s;
}

// Every difference, one line each: path: old -> new.
void diff(const json& a, const json& b, const std::string& path, const Tolerances& tol, std::vector<std::string>& out) {
  if (a.is_number() && b.is_number()) {
    const double x = a.get<double>(), y = b.get<double>();
    const Tolerance t = tol.at(path);
    if (!(std::abs(y - x) <= t.abs + t.rel * std::abs(x)) && !(std::isnan(x) && std::isnan(y)))
      out.push_back(path + ": " + shown(a) + " -> " + shown(b));
    return;
  }
  if (a.type() != b.type()) {
    out.push_back(path + ": " + shown(a) + " -> " + shown(b));
    return;
  }
  if (a.is_object()) {
    for (const auto& [k, v] : a.items()) {
      const std::string p = path.empty() ? k : path + "." + k;
      if (!b.contains(k))
        out.push_back(p + ": " + shown(v) + " -> (gone)");
      else
        diff(v, b.at(k), p, tol, out);
    }
    for (const auto& [k, v] : b.items())
      if (!a.contains(k)) out.push_back((path.empty() ? k : path + "." + k) + ": (new) -> " + shown(v));
    return;
  }
  if (a.is_array()) {
    // Arrays of named entries (explain's effects) are matched by name: a new rank order is
    // one line, not every entry after it.
    auto named = [](const json& x) {
      for (const auto& v : x)
        if (!v.is_object() || !v.contains("name") || !v["name"].is_string()) return false;
      return !x.empty();
    };
    if (named(a) && named(b)) {
      std::vector<std::string> order_a, order_b;
      for (const auto& v : a) order_a.push_back(v["name"]);
      for (const auto& v : b) order_b.push_back(v["name"]);
      if (order_a != order_b) out.push_back(path + " order: " + json(order_a).dump() + " -> " + json(order_b).dump());
      for (const auto& v : a) {
        const std::string p = path + "[" + v["name"].get<std::string>() + "]";
        const json* w = nullptr;
        for (const auto& x : b)
          if (x["name"] == v["name"]) w = &x;
        if (!w)
          out.push_back(p + ": (gone)");
        else
          diff(v, *w, p, tol, out);
      }
      for (const auto& x : b) {
        bool had = false;
        for (const auto& v : a) had = had || v["name"] == x["name"];
        if (!had) out.push_back(path + "[" + x["name"].get<std::string>() + "]: (new)");
      }
      return;
    }
    if (a.size() != b.size())
      out.push_back(path + ": " + std::to_string(a.size()) + " entries -> " + std::to_string(b.size()));
    for (std::size_t i = 0; i < std::min(a.size(), b.size()); ++i)
      diff(a[i], b[i], path + "[" + std::to_string(i) + "]", tol, out);
    return;
  }
  if (a != b) out.push_back(path + ": " + shown(a) + " -> " + shown(b));
}

// The command's standard output and exit status (analyze exits 2/3 with a document).
// analyze without its search for a measurable variant: that search simulates variants (45 s
// of a not-measurable run's 55 s) and is eical plan's, tested by NotMeasurable.*; the
// golden pins what the run's own analysis says.
std::pair<std::string, int> run_cli(const std::string& command, const fs::path& run) {
  const std::string cmd = std::string(EICAL_CLI) + " " + command + " '" + run.string() + "' --json" +
                          (command == "analyze" ? " --no-suggest" : "") + " 2>/dev/null";
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) return {"", -1};
  std::string out;
  char buf[65536];
  std::size_t n = 0;
  while ((n = fread(buf, 1, sizeof buf, p)) > 0) out.append(buf, n);
  const int st = pclose(p);
  return {out, WIFEXITED(st) ? WEXITSTATUS(st) : -1};
}

class Golden : public ::testing::TestWithParam<Case> {};

TEST_P(Golden, OutputEqualsTheCommittedOneWithinTolerance) {
  const Case& c = GetParam();
  const Tolerances tol = read_tolerances();
  const auto [text, exit_code] = run_cli(c.command, c.run);
  json doc;
  try {
    doc = json::parse(text);
  } catch (const json::parse_error& e) {
    FAIL() << "eical " << c.command << " " << c.run << " printed no JSON document (exit " << exit_code
           << "): " << e.what();
  }
  json now = canonical(doc, tol);
  now["exit_code"] = exit_code;
  const fs::path file = kExpected / c.command / (c.name + ".json");
  if (std::getenv("EICAL_GOLDEN_UPDATE")) {
    fs::create_directories(file.parent_path());
    std::ofstream(file) << now.dump(1) << "\n";
    SUCCEED() << "wrote " << file;
    return;
  }
  ASSERT_TRUE(fs::exists(file)) << "no golden output " << file << ": EICAL_GOLDEN_UPDATE=1 ctest -L golden writes it";
  std::ifstream in(file);
  const json before = json::parse(in);
  std::vector<std::string> changes;
  diff(before, now, "", tol, changes);
  std::ostringstream msg;
  for (const auto& l : changes) msg << "  " << l << "\n";
  EXPECT_TRUE(changes.empty())
      << "eical " << c.command << " " << c.name << ": " << changes.size() << " changed keys (old -> new):\n"
      << msg.str() << "If the change is meant: EICAL_GOLDEN_UPDATE=1 ctest -L golden, read the diff, commit it.";
}

// The diff itself: a figure moved beyond its tolerance is named with both values; one within
// it is not; a key that appears or goes is named.
TEST(GoldenDiff, NamesAChangedFigureAndOnlyIt) {
  Tolerances tol;
  tol.fallback = {1e-9, 1e-9};
  tol.rules.push_back({"uncertainty_k2.", {1e-3, 0.0}});
  const json a = {{"circle", {{"G_um", 5.0}, {"F_um", 1.0}}}, {"uncertainty_k2", {{"circle.G_um", 10.0}}}, {"gone", 1}};
  const json b = {
      {"circle", {{"G_um", 5.1}, {"F_um", 1.0}}}, {"uncertainty_k2", {{"circle.G_um", 10.005}}}, {"new", 2}};
  std::vector<std::string> out;
  diff(a, b, "", tol, out);
  ASSERT_EQ(out.size(), 3u);
  EXPECT_EQ(out[0], "circle.G_um: 5.0 -> 5.1");
  EXPECT_EQ(out[1], "gone: 1 -> (gone)");
  EXPECT_EQ(out[2], "new: (new) -> 2");
}

TEST(GoldenDiff, NamedEntriesAreMatchedByName) {
  const Tolerances tol;
  const json a = {{"effects", {{{"name", "x"}, {"size", 1.0}}, {{"name", "y"}, {"size", 2.0}}}}};
  const json b = {{"effects", {{{"name", "y"}, {"size", 2.0}}, {{"name", "x"}, {"size", 1.5}}}}};
  std::vector<std::string> out;
  diff(a, b, "", tol, out);
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(out[0], R"(effects order: ["x","y"] -> ["y","x"])");
  EXPECT_EQ(out[1], "effects[x].size: 1.0 -> 1.5");
}

TEST(GoldenDiff, LongNumericArraysAreSummarised) {
  Tolerances tol;
  json a = json::array();
  for (int i = 0; i < 100; ++i) a.push_back(i % 2 ? 1.0 : -1.0);
  const json c = canonical(json{{"trace", a}}, tol);
  EXPECT_EQ(c["trace"]["summary_n"], 100);
  EXPECT_DOUBLE_EQ(c["trace"]["summary_rms"].get<double>(), 1.0);
  EXPECT_DOUBLE_EQ(c["trace"]["summary_min"].get<double>(), -1.0);
}

std::string case_name(const ::testing::TestParamInfo<Case>& info) {
  std::string s = info.param.command + "_" + info.param.name;
  for (char& ch : s)
    if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
  return s;
}

INSTANTIATE_TEST_SUITE_P(SampleRuns, Golden, ::testing::ValuesIn(cases()), case_name);

TEST(GoldenData, CommittedRunsPresent) {
  try {
    EXPECT_GE(eical::test::committed_runs().size(), 6u);
  } catch (const std::exception& e) {
    FAIL() << e.what();
  }
}

// Every expected document has its run, committed or extra; without the extra folder the
// documents of its runs wait unread, and this says so.
TEST(GoldenData, ExtraRunsPresent) {
  std::set<std::string> have;
  for (const auto& c : cases()) have.insert(c.command + "/" + c.name + ".json");
  std::vector<std::string> unread;
  for (const auto& e : fs::recursive_directory_iterator(kExpected))
    if (e.is_regular_file() && !have.count(fs::relative(e.path(), kExpected).string()))
      unread.push_back(fs::relative(e.path(), kExpected).string());
  if (!unread.empty() && eical::test::extra_runs().empty())
    GTEST_SKIP() << unread.size() << " expected documents are of runs in EICAL_EXTRA_DATA = " << EICAL_EXTRA_DATA
                 << ", which has none: not compared";
  EXPECT_TRUE(unread.empty()) << "expected documents without a run, e.g. " << (unread.empty() ? "" : unread.front());
}

}  // namespace
