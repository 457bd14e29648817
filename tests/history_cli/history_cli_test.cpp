// `eical history add | list | show | trend | compare` through the real binary, against a
// SQLite file and the suite's PostgreSQL server alike: what a user types and reads, the
// JSON a program reads (identical from both stores), the HTML pages, and errors that say
// what is wrong.
#include "cli_support.hpp"

#include <nlohmann/json.hpp>

namespace eical::test {
namespace {

using nlohmann::json;

// Four circle tests of one machine: backlash X 6.1 µm until the compensation, then 0.8 µm;
// and one of another machine whose run id collides with the first.
struct Fixture {
  fs::path dir;
  std::string db;
  std::vector<std::string> runs;
};

Fixture make(Backend b) {
  Fixture fx;
  fx.dir = scratch("cli");
  fx.db = fresh_store(b, fx.dir);
  const char* times[] = {"2026-10-01T08:00:00Z", "2026-10-15T08:00:00Z", "2026-11-01T08:00:00Z",
                         "2026-11-15T08:00:00Z"};
  const double backlash[] = {6.1, 6.3, 0.8, 0.8};
  for (int i = 0; i < 4; ++i) {
    CircleFigures f;
    f.backlash_x_um = backlash[i];
    f.u_backlash_x_um = 0.4;
    fx.runs.push_back(
        write_run_dir(fx.dir / "runs", "maho-1", "circle-" + std::to_string(i + 1), times[i], f).string());
  }
  fx.runs.push_back(write_run_dir(fx.dir / "other", "hermle-2", "circle-1", "2026-10-02T08:00:00Z", {}).string());
  return fx;
}

json parse(const CliResult& r) {
  const auto j = json::parse(r.out, nullptr, false);
  EXPECT_FALSE(j.is_discarded()) << r.out;
  return j;
}

class HistoryCli : public ::testing::TestWithParam<Backend> {};

TEST_P(HistoryCli, AddListShowTrendCompare) {
  const auto fx = make(GetParam());
  std::vector<std::string> add = {"history", "add"};
  add.insert(add.end(), fx.runs.begin(), fx.runs.end());
  add.insert(add.end(), {"--db", fx.db});
  auto r = eical_cli(add);
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("added maho-1 circle-1 (circle, 2026-10-01 08:00:00 UTC, verdict ok)"), std::string::npos)
      << r.out;
  r = eical_cli(add);  // again: nothing twice
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("already stored: maho-1 circle-4"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("added"), std::string::npos) << r.out;

  r = eical_cli({"history", "list", "--db", fx.db, "--machine", "maho-1", "--json"});
  ASSERT_EQ(r.code, 0) << r.out;
  const auto list = parse(r);
  ASSERT_EQ(list["results"].size(), 4u);
  EXPECT_EQ(list["results"][0]["run_id"], "circle-1");
  EXPECT_EQ(list["results"][3]["verdict"], "ok");
  r = eical_cli({"history", "list", "--db", fx.db, "--since", "2026-10-10", "--until", "2026-11"});
  EXPECT_NE(r.out.find("circle-2"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("1 result\n"), std::string::npos) << r.out;

  r = eical_cli({"history", "show", "circle-3@maho-1", "--db", fx.db});
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("diagnostics.backlash_x_um"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("0.8 ± 0.4 µm"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("eical 0.1.0"), std::string::npos) << r.out;
  r = eical_cli({"history", "show", "circle-3", "--db", fx.db, "--json"});
  const auto shown = parse(r);
  EXPECT_EQ(shown["format"], "eical-history-record/1");
  EXPECT_EQ(shown["run_path"], (fx.dir / "runs" / "circle-3").string());
  bool found = false;
  for (const auto& f : shown["figures"]) {
    if (f["name"] != "diagnostics.backlash_x_um") continue;
    found = true;
    EXPECT_EQ(f["value"], 0.8);
    EXPECT_EQ(f["uncertainty_k2"], 0.4);
  }
  EXPECT_TRUE(found);

  const fs::path trend_html = fx.dir / "trend.html";
  r = eical_cli({"history", "trend", "diagnostics.backlash_x_um", "--machine", "maho-1", "--db", fx.db, "--html",
                 trend_html.string()});
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("6.1 ± 0.4 µm"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("maho-1: 6.1 ± 0.4 µm (2026-10-01) → 0.8 ± 0.4 µm (2026-11-15), drift"), std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("(significant)"), std::string::npos) << r.out;
  EXPECT_NE(slurp(trend_html).find("<svg"), std::string::npos);
  const auto trend = parse(eical_cli({"history", "trend", "diagnostics.backlash_x_um", "--db", fx.db, "--json"}));
  ASSERT_EQ(trend["points"].size(), 5u);  // the fleet: both machines
  EXPECT_EQ(trend["machines"].size(), 2u);
  EXPECT_EQ(trend["unit"], "µm");

  const fs::path cmp_html = fx.dir / "compare.html";
  r = eical_cli(
      {"history", "compare", "circle-1@maho-1", "circle-4@maho-1", "--db", fx.db, "--html", cmp_html.string()});
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("backlash X went from 6.1 ± 0.4 to 0.8 ± 0.4 µm: -5.3 ± 0.6 µm, significant"), std::string::npos)
      << r.out;
  EXPECT_NE(
      r.out.find("circular deviation G went from 6.3 ± 1.1 to 6.3 ± 1.1 µm: 0.0 ± 1.6 µm, within the uncertainty"),
      std::string::npos)
      << r.out;
  const std::string page = slurp(cmp_html);
  EXPECT_NE(page.find("Polar plots overlaid"), std::string::npos);
  EXPECT_NE(page.find("before: circle-1 (2026-10-01)"), std::string::npos);
  EXPECT_NE(page.find("after: circle-4 (2026-11-15)"), std::string::npos);
  EXPECT_NE(page.find("Trends of the changed figures"), std::string::npos);
  const auto cmp =
      parse(eical_cli({"history", "compare", "circle-1", "circle-4", "--machine", "maho-1", "--db", fx.db, "--json"}));
  for (const auto& f : cmp["figures"]) {
    if (f["name"] == "diagnostics.backlash_x_um") {
      EXPECT_EQ(f["judgement"], "significant");
    }
  }
  fs::remove_all(fx.dir);
}

TEST_P(HistoryCli, ErrorsSayWhatIsWrong) {
  const auto fx = make(GetParam());
  std::vector<std::string> add = {"history", "add"};
  add.insert(add.end(), fx.runs.begin(), fx.runs.end());
  add.insert(add.end(), {"--db", fx.db});
  ASSERT_EQ(eical_cli(add).code, 0);
  auto r = eical_cli({"history", "show", "circle-1", "--db", fx.db}, true);
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.out.find("run circle-1 is stored for several machines (hermle-2, maho-1)"), std::string::npos) << r.out;
  r = eical_cli({"history", "compare", "circle-9", "circle-1@maho-1", "--db", fx.db}, true);
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.out.find("no result circle-9"), std::string::npos) << r.out;
  r = eical_cli({"history", "trend", "diagnostics.backlash", "--db", fx.db}, true);
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.out.find("no figure diagnostics.backlash"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("diagnostics.backlash_x_um"), std::string::npos) << r.out;  // what there is
  fs::create_directories(fx.dir / "broken");
  { std::ofstream(fx.dir / "broken" / "run.toml") << "format = \"eical-run/1\"\n"; }
  r = eical_cli({"history", "add", (fx.dir / "broken").string(), "--db", fx.db}, true);
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.out.find("run.toml"), std::string::npos) << r.out;
  fs::remove_all(fx.dir);
}

INSTANTIATE_TEST_SUITE_P(Backends, HistoryCli, ::testing::Values(Backend::sqlite, Backend::postgresql), backend_name);

// The same runs into a SQLite file and a PostgreSQL database: the JSON answers are equal.
TEST(HistoryCliBackends, BothStoresPrintTheSameAnswers) {
  const auto a = make(Backend::sqlite);
  const std::string pg_db = fresh_store(Backend::postgresql, a.dir);
  for (const std::string& db : {a.db, pg_db}) {
    std::vector<std::string> add = {"history", "add"};
    add.insert(add.end(), a.runs.begin(), a.runs.end());
    add.insert(add.end(), {"--db", db});
    ASSERT_EQ(eical_cli(add).code, 0);
  }
  const std::vector<std::vector<std::string>> queries = {
      {"history", "list", "--json"},
      {"history", "trend", "diagnostics.backlash_x_um", "--json"},
      {"history", "trend", "circle.circular_deviation_G_um", "--machine", "maho-1", "--json"},
      {"history", "compare", "circle-2@maho-1", "circle-3@maho-1", "--json"},
      {"history", "show", "circle-2@maho-1", "--json"}};
  for (auto q : queries) {
    auto qa = q, qb = q;
    qa.insert(qa.end(), {"--db", a.db}), qb.insert(qb.end(), {"--db", pg_db});
    auto ja = parse(eical_cli(qa)), jb = parse(eical_cli(qb));
    ja.erase("store"), jb.erase("store");
    EXPECT_EQ(ja, jb) << q[1];
  }
  fs::remove_all(a.dir);
}

TEST(HistoryCliSqlite, AnalysesARunWithoutResultAndRefusesAMissingStore) {
  const fs::path dir = scratch("cli-sim");
  auto r = eical_cli({"simulate", "--program", "circle", "-o", (dir / "sim").string()});
  ASSERT_EQ(r.code, 0) << r.out;
  r = eical_cli({"history", "add", (dir / "sim").string(), "--machine", "bench-1", "--db", (dir / "h.db").string()});
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("added bench-1"), std::string::npos) << r.out;
  const auto shown =
      parse(eical_cli({"history", "show", "sim-circle-r10-f2500-s1", "--db", (dir / "h.db").string(), "--json"}));
  EXPECT_EQ(shown["software_version"], "eical 0.1.0");
  EXPECT_TRUE(shown["document"]["circle"]["circular_deviation_G_um"].is_number());
  r = eical_cli({"history", "list", "--db", (dir / "none.db").string()}, true);
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.out.find("no history store there"), std::string::npos) << r.out;
  fs::remove_all(dir);
}

}  // namespace
}  // namespace eical::test
