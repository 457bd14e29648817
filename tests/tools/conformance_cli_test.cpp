// `eical analyze --tolerances`: each toleranced figure and the run decided by ISO 14253-1
// with U, in the text, the JSON and the exit status (docs/command-line.md), from the same
// tolerance file `eical report` takes.
#include "drivers/run_io/run_writer.hpp"
#include "sim/simulate.hpp"

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <nlohmann/json.hpp>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>

namespace eical {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

std::string run_cli(const std::string& args, int& status) {
  FILE* p = ::popen((std::string(EICAL_CLI) + " " + args + " 2>/dev/null").c_str(), "r");
  std::string out;
  char buf[4096];
  while (p && std::fgets(buf, sizeof buf, p)) out += buf;
  const int st = p ? ::pclose(p) : -1;
  status = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  return out;
}

fs::path tolerance_file(const fs::path& dir, const std::string& name, double g_um) {
  const fs::path f = dir / name;
  std::ofstream(f) << "format = \"eical-tolerances/1\"\n[circle]\nG_um = " << g_um << "\n";
  return f;
}

TEST(ConformanceCli, ToleranceWideNarrowAndStraddledByU) {
  const fs::path dir = fs::temp_directory_path() / ("conformance-" + std::to_string(std::random_device{}()));
  drivers::write_run(sim::simulate(sim::circle_scenario(10.0, 2500.0, 1, "ccw", 3)), dir / "run", {});
  const std::string run = (dir / "run").string() + " --no-suggest --draws 40";
  int status = -1;
  const json plain = json::parse(run_cli("analyze --json " + run, status));
  EXPECT_FALSE(plain["quality"].contains("conformance"));
  const double g = plain["circle"]["circular_deviation_G_um"],
               u = plain["uncertainty_k2"]["circle.circular_deviation_G_um"];
  ASSERT_GT(u, 0.0);
  const std::string verdict = plain["quality"]["verdict"];
  struct Case {
    double tolerance_um;
    const char* decision;
    int exit_if_ok;
  };
  for (const Case c : {Case{g + u + 0.5, "conforming", 0}, Case{g, "undecided", 5}}) {
    const fs::path t = tolerance_file(dir, std::string(c.decision) + ".toml", c.tolerance_um);
    const json doc = json::parse(run_cli("analyze --json --tolerances " + t.string() + " " + run, status));
    ASSERT_TRUE(doc["quality"].contains("conformance")) << doc["quality"].dump();
    const json& conf = doc["quality"]["conformance"];
    EXPECT_EQ(conf["overall"], c.decision) << "tolerance " << c.tolerance_um << ", G " << g << " ± " << u;
    ASSERT_EQ(conf["figures"].size(), 1u);
    EXPECT_EQ(conf["figures"][0]["key"], "circle.circular_deviation_G_um");
    EXPECT_EQ(conf["figures"][0]["decision"], c.decision);
    // The exit status: the verdict's unless it is ok, then the decision's. With tolerances
    // the verdict is judged against them: a decision proven either way is never
    // not_measurable (the banner and the table tell one story); undecided keeps the
    // verdict the run had without them.
    const std::string judged = doc["quality"]["verdict"];
    if (std::string(c.decision) == "undecided")
      EXPECT_EQ(judged, verdict);
    else
      EXPECT_NE(judged, "not_measurable") << doc["quality"].dump();
    EXPECT_EQ(status, judged == "ok" ? c.exit_if_ok : judged == "degraded" ? 2 : 3);
    const std::string text = run_cli("analyze --tolerances " + t.string() + " " + run, status);
    EXPECT_NE(text.find("against the tolerances (ISO 14253-1"), std::string::npos) << text;
    // The report's banner says the verdict and the decision together (one report: each
    // renders its 100 draws).
    if (std::string(c.decision) != "undecided") continue;
    const fs::path rep = dir / (std::string("report-") + c.decision);
    (void)run_cli("report " + (dir / "run").string() + " --tolerances " + t.string() + " -o " + rep.string(), status);
    ASSERT_EQ(status, 0);
    std::ifstream html(rep / "report.html");
    const std::string page{std::istreambuf_iterator<char>(html), std::istreambuf_iterator<char>()};
    // (The report draws 100 times where this analysis drew 40: its U, and so its decision,
    // may differ; what must hold is that the banner says the table's decision.)
    const std::string banner = "against the tolerances: <b>", table = "(ISO 14253-1 with U, k = 2): ";
    const auto at_banner = page.find(banner), at_table = page.find(table);
    ASSERT_NE(at_banner, std::string::npos);
    ASSERT_NE(at_table, std::string::npos);
    const std::string said =
        page.substr(at_banner + banner.size(), page.find('<', at_banner + banner.size()) - at_banner - banner.size());
    EXPECT_EQ(page.compare(at_table + table.size(), said.size(), said), 0) << said;
  }
  if (g - u > 0.5) {  // a figure resolved above a tolerance below it: non-conformance proven
    const fs::path t = tolerance_file(dir, "tight.toml", g - u - 0.25);
    const json doc = json::parse(run_cli("analyze --json --tolerances " + t.string() + " " + run, status));
    EXPECT_EQ(doc["quality"]["conformance"]["overall"], "nonconforming");
  }
  // A tolerance file with a typo is refused by name before anything is analysed.
  const fs::path bad = dir / "bad.toml";
  std::ofstream(bad) << "format = \"eical-tolerances/1\"\n[circle]\nG_mu = 3\n";
  (void)run_cli("analyze --tolerances " + bad.string() + " " + run, status);
  EXPECT_EQ(status, 1);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace eical
