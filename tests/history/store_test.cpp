// The store against both backends, the same tests: what goes in comes out exactly, a
// result is keyed by machine and run id, listings and trends filter and order alike, and
// SQLite and PostgreSQL give identical answers for the same results.
#include "history/store/store.hpp"
#include "history/record/result_record.hpp"
#include "history/store/schema.hpp"
#include "history_support.hpp"

namespace eical::test {
namespace {

using history::AddOutcome;
using history::Filter;
using history::Record;
using history::Store;

Record record(const std::string& machine, const std::string& run, const std::string& time,
              const CircleFigures& f = {}) {
  return history::record_from_result(circle_result(run, f), {machine, time, "/runs/" + run, std::nullopt, ""});
}

class StoreTest : public ::testing::TestWithParam<Backend> {
 protected:
  void SetUp() override {
    dir_ = scratch("store");
    location_ = fresh_store(GetParam(), dir_);
    store_ = Store::open(location_, {.create = true});
  }
  void TearDown() override {
    store_.reset();
    fs::remove_all(dir_);
  }
  fs::path dir_;
  std::string location_;
  std::unique_ptr<Store> store_;
};

TEST_P(StoreTest, WhatGoesInComesOutExactly) {
  CircleFigures f;
  f.backlash_x_um = 0.1 + 0.2;  // not representable exactly: must survive text transport bit for bit
  const Record in = record("maho-1", "r1", "2026-11-12T09:11:00Z", f);
  EXPECT_EQ(store_->add(in), AddOutcome::added);
  const auto found = store_->find("r1");
  ASSERT_EQ(found.size(), 1u);
  const Record& out = found[0];
  EXPECT_EQ(out.machine, in.machine);
  EXPECT_EQ(out.program, "circle");
  EXPECT_EQ(out.measured_at, in.measured_at);
  EXPECT_EQ(out.verdict, in.verdict);
  EXPECT_EQ(out.degraded, in.degraded);
  EXPECT_EQ(out.run_path, in.run_path);
  EXPECT_EQ(out.software_version, in.software_version);
  EXPECT_EQ(out.sensor_calibration, in.sensor_calibration);
  ASSERT_EQ(out.figures.size(), in.figures.size());
  for (std::size_t i = 0; i < in.figures.size(); ++i) {
    EXPECT_EQ(out.figures[i].name, in.figures[i].name);
    EXPECT_EQ(out.figures[i].value, in.figures[i].value) << in.figures[i].name;
    EXPECT_EQ(out.figures[i].uncertainty_k2, in.figures[i].uncertainty_k2) << in.figures[i].name;
  }
  EXPECT_EQ(out.figure("diagnostics.backlash_x_um")->value.value(), 0.1 + 0.2);
  EXPECT_EQ(nlohmann::json::parse(out.document), nlohmann::json::parse(in.document));
}

TEST_P(StoreTest, ResultsWithoutUncertaintyAndVerdictAreNull) {
  CircleFigures f;
  f.uncertainty = false, f.verdict = false;
  ASSERT_EQ(store_->add(record("maho-1", "old", "2026-01-01T00:00:00Z", f)), AddOutcome::added);
  const auto out = store_->find("old").at(0);
  EXPECT_FALSE(out.verdict);
  for (const auto& fig : out.figures) EXPECT_FALSE(fig.uncertainty_k2) << fig.name;
  EXPECT_FALSE(out.figure("circle.circular_hysteresis_H_um")->value);  // not determined
}

TEST_P(StoreTest, AResultIsKeyedByMachineAndRunId) {
  EXPECT_EQ(store_->add(record("maho-1", "r1", "2026-11-12T09:00:00Z")), AddOutcome::added);
  CircleFigures other;
  other.backlash_x_um = 99.0;
  EXPECT_EQ(store_->add(record("maho-1", "r1", "2026-11-12T09:00:00Z", other)), AddOutcome::duplicate);
  EXPECT_EQ(store_->find("r1").at(0).figure("diagnostics.backlash_x_um")->value.value(), 6.1);  // the first stays
  EXPECT_EQ(store_->add(record("hermle-2", "r1", "2026-11-12T09:00:00Z")),
            AddOutcome::added);  // same run id, other machine
  EXPECT_EQ(store_->count(), 2u);
  EXPECT_EQ(store_->find("r1").size(), 2u);
  EXPECT_EQ(store_->find("r1", "hermle-2").size(), 1u);
  const auto outcomes = store_->add_many(
      {record("maho-1", "r1", "2026-11-12T09:00:00Z"), record("maho-1", "r2", "2026-11-13T09:00:00Z")});
  EXPECT_EQ(outcomes, (std::vector<AddOutcome>{AddOutcome::duplicate, AddOutcome::added}));
  EXPECT_EQ(store_->count(), 3u);
}

TEST_P(StoreTest, ListAndTrendFilterAndOrderByTime) {
  // Added out of time order; two machines.
  const char* times[] = {"2026-03-01T08:00:00Z", "2026-01-01T08:00:00Z", "2026-02-01T08:00:00Z",
                         "2026-04-01T08:00:00Z"};
  for (int i = 0; i < 4; ++i) {
    CircleFigures f;
    f.backlash_x_um = 1.0 + i, f.u_backlash_x_um = 0.1 * (i + 1);
    ASSERT_EQ(store_->add(record("maho-1", "m" + std::to_string(i), times[i], f)), AddOutcome::added);
  }
  ASSERT_EQ(store_->add(record("hermle-2", "h0", "2026-02-15T08:00:00Z")), AddOutcome::added);
  const auto all = store_->list({});
  ASSERT_EQ(all.size(), 5u);
  EXPECT_EQ(all.front().run_id, "m1");
  EXPECT_EQ(all.back().run_id, "m3");
  EXPECT_EQ(store_->list({.machine = "hermle-2"}).size(), 1u);
  const auto feb_mar = store_->list({.machine = "maho-1", .since = "2026-02", .until = "2026-04"});
  ASSERT_EQ(feb_mar.size(), 2u);
  EXPECT_EQ(feb_mar[0].run_id, "m2");
  EXPECT_EQ(feb_mar[1].run_id, "m0");
  const auto last2 = store_->list({.machine = "maho-1", .limit = 2});
  ASSERT_EQ(last2.size(), 2u);
  EXPECT_EQ(last2[0].run_id, "m0");  // newest two, oldest first
  EXPECT_EQ(last2[1].run_id, "m3");
  const auto t = store_->trend("diagnostics.backlash_x_um", {.machine = "maho-1"});
  ASSERT_EQ(t.size(), 4u);
  const double want[] = {2.0, 3.0, 1.0, 4.0};  // m1, m2, m0, m3
  for (std::size_t i = 0; i < 4; ++i) EXPECT_EQ(t[i].value.value(), want[i]);
  EXPECT_EQ(t[0].uncertainty_k2.value(), 0.2);
  EXPECT_EQ(store_->trend("diagnostics.backlash_x_um", {}).size(), 5u);  // the fleet
  EXPECT_TRUE(store_->trend("no.such_figure_um", {}).empty());
  EXPECT_EQ(store_->machines(), (std::vector<std::string>{"hermle-2", "maho-1"}));
  const auto names = store_->figure_names("maho-1");
  EXPECT_NE(std::find(names.begin(), names.end(), "diagnostics.backlash_x_um"), names.end());
}

INSTANTIATE_TEST_SUITE_P(Backends, StoreTest, ::testing::Values(Backend::sqlite, Backend::postgresql), backend_name);

// One set of results into both stores: every query answers the same.
TEST(StoreBackends, SQLiteAndPostgreSQLGiveTheSameAnswers) {
  const fs::path dir = scratch("same");
  auto a = Store::open(fresh_store(Backend::sqlite, dir), {.create = true});
  auto b = Store::open(fresh_store(Backend::postgresql, dir), {.create = true});
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0.0, 10.0);
  std::vector<Record> rs;
  for (int i = 0; i < 40; ++i) {
    CircleFigures f;
    f.backlash_x_um = u(rng), f.u_backlash_x_um = u(rng) / 10, f.g_um = u(rng), f.verdict = i % 3 != 0,
    f.uncertainty = i % 5 != 0;
    char t[32];
    std::snprintf(t, sizeof t, "2026-%02d-%02dT%02d:00:00Z", 1 + i % 12, 1 + i % 28, i % 24);
    rs.push_back(record(i % 2 ? "maho-1" : "Hermle-2", "run-" + std::to_string(i % 17) + (i >= 17 ? "b" : ""), t, f));
  }
  a->add_many(rs);
  b->add_many(rs);
  auto same_list = [&](const Filter& f) {
    const auto x = a->list(f), y = b->list(f);
    ASSERT_EQ(x.size(), y.size());
    for (std::size_t i = 0; i < x.size(); ++i) {
      EXPECT_EQ(x[i].machine, y[i].machine);
      EXPECT_EQ(x[i].run_id, y[i].run_id);
      EXPECT_EQ(x[i].measured_at, y[i].measured_at);
      EXPECT_EQ(x[i].verdict, y[i].verdict);
    }
  };
  same_list({});
  same_list({.machine = "maho-1"});
  same_list({.since = "2026-03", .until = "2026-09-15"});
  same_list({.limit = 7});
  for (const char* fig :
       {"diagnostics.backlash_x_um", "circle.circular_deviation_G_um", "circle.circular_hysteresis_H_um"}) {
    for (const std::string m : {"", "maho-1"}) {
      const auto x = a->trend(fig, {.machine = m}), y = b->trend(fig, {.machine = m});
      ASSERT_EQ(x.size(), y.size());
      for (std::size_t i = 0; i < x.size(); ++i) {
        EXPECT_EQ(x[i].run_id, y[i].run_id);
        EXPECT_EQ(x[i].value, y[i].value);
        EXPECT_EQ(x[i].uncertainty_k2, y[i].uncertainty_k2);
      }
    }
  }
  EXPECT_EQ(a->machines(), b->machines());
  EXPECT_EQ(a->figure_names(""), b->figure_names(""));
  const auto fa = a->find("run-3"), fb = b->find("run-3");
  ASSERT_EQ(fa.size(), fb.size());
  for (std::size_t i = 0; i < fa.size(); ++i) EXPECT_EQ(fa[i].machine, fb[i].machine);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace eical::test
