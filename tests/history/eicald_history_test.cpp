// eicald appends each result it evaluates to the history ([history]), SQLite and
// PostgreSQL alike: the stored figures are those of the run's result.json, with the run
// directory, the software version and the sensor calibration. With the database away the
// measurement is still recorded and evaluated, the result waits in the spool, the log
// names the cause, and the result enters the store when the database is back.
#include "daemon/config/daemon_config.hpp"
#include "daemon/service/service.hpp"
#include "drivers/dds/domain_claim.hpp"
#include "history/record/result_record.hpp"
#include "history/spool/sink.hpp"
#include "history/sql/sqlite_connection.hpp"
#include "history/store/store.hpp"
#include "history_support.hpp"

#include <fstream>

namespace eical::test {
namespace {

daemon::DaemonConfig one_measurement(const fs::path& dir, const std::string& db) {
  daemon::DaemonConfig c;
  c.source.kind = "sim";
  c.source.pacing = "free_running";
  c.source.sim_repeats = 2;
  c.source.sim_repeat_program = false;
  c.triggers.inputs = {"frame"};
  // The loopback bus on a domain of its own (eicald refuses a DDS configuration that does
  // not exist, so "no bus" is no longer a way to start it); the bus is not what this tests.
  c.dds.domain_id = drivers::dds::claim_free_domain();
  c.dds.config_uri = "file://" EICAL_SOURCE_DIR "/config/cyclonedds-loopback.xml";
  c.recording.dir = dir / "runs";
  c.recording.gzip = false;
  c.realtime.sched_fifo_priority = 0;
  c.realtime.mlockall = false;
  c.limits.max_measurement_s = 30.0;
  c.machine.name = "maho-test";
  c.history = {true, db, dir / "spool", 0.2};
  return c;
}

fs::path the_run(const fs::path& runs) {
  std::vector<fs::path> out;
  for (const auto& e : fs::directory_iterator(runs))
    if (e.is_directory() && e.path().filename().string()[0] != '.') out.push_back(e.path());
  EXPECT_EQ(out.size(), 1u);
  return out.empty() ? fs::path() : out[0];
}

nlohmann::json read_json(const fs::path& p) {
  std::ifstream is(p);
  return nlohmann::json::parse(is);
}

void expect_stored_as_written(history::Store& s, const fs::path& run) {
  const auto doc = read_json(run / "result.json");
  const auto found = s.find(doc["run_id"].get<std::string>(), "maho-test");
  ASSERT_EQ(found.size(), 1u);
  const auto& r = found[0];
  EXPECT_EQ(r.run_path, run.string());
  EXPECT_EQ(r.software_version.value_or(""), doc["software"].get<std::string>());
  EXPECT_EQ(r.sensor_calibration, "datasheet");
  EXPECT_EQ(r.program, "circle");
  const auto want = history::figures_of(doc);
  ASSERT_FALSE(want.empty());
  ASSERT_EQ(r.figures.size(), want.size());
  for (std::size_t i = 0; i < want.size(); ++i) {
    EXPECT_EQ(r.figures[i].name, want[i].name);
    EXPECT_EQ(r.figures[i].value, want[i].value) << want[i].name;
    EXPECT_EQ(r.figures[i].uncertainty_k2, want[i].uncertainty_k2) << want[i].name;
  }
  EXPECT_NE(r.figure("circle.circular_deviation_G_um"), nullptr);
}

class EicaldHistory : public ::testing::TestWithParam<Backend> {};

TEST_P(EicaldHistory, EachEvaluatedResultEntersTheStore) {
  const fs::path dir = scratch("eicald");
  const std::string db = fresh_store(GetParam(), dir);
  std::atomic<bool> stop{false};
  daemon::Service(one_measurement(dir, db)).run(stop, [](const daemon::ServiceStatus&) {});
  const fs::path run = the_run(dir / "runs");
  ASSERT_TRUE(fs::exists(run / "result.json"));
  auto s = history::Store::open(db);
  EXPECT_EQ(s->count(), 1u);
  expect_stored_as_written(*s, run);
  EXPECT_TRUE(history::Spool(dir / "spool").waiting().empty());
  fs::remove_all(dir);
}

INSTANTIATE_TEST_SUITE_P(Backends, EicaldHistory, ::testing::Values(Backend::sqlite, Backend::postgresql),
                         backend_name);

TEST(EicaldHistoryFaults, WithTheDatabaseAwayTheResultWaitsAndEntersWhenItIsBack) {
  const fs::path dir = scratch("eicald-away");
  const std::string db = fresh_store(Backend::postgresql, dir);
  (void)history::Store::open(db, {.create = true});
  pg().stop();
  std::atomic<bool> stop{false};
  std::vector<std::string> faults;
  ::testing::internal::CaptureStderr();
  daemon::Service(one_measurement(dir, db)).run(stop, [&](const daemon::ServiceStatus& st) {
    faults.push_back(st.fault);
  });
  const std::string log = ::testing::internal::GetCapturedStderr();
  // Recorded and evaluated as always.
  const fs::path run = the_run(dir / "runs");
  ASSERT_TRUE(fs::exists(run / "result.json"));
  EXPECT_TRUE(read_json(run / "result.json")["circle"]["circular_deviation_G_um"].is_number());
  // Waiting on disk, the cause in the journal.
  EXPECT_EQ(history::Spool(dir / "spool").waiting().size(), 1u);
  EXPECT_NE(log.find("history: history store postgresql://"), std::string::npos) << log;
  EXPECT_NE(log.find("results wait in " + (dir / "spool").string()), std::string::npos) << log;
  // The database is back; the next start of eicald (its sink) moves the result in.
  pg().start();
  history::Sink sink({db, dir / "spool", 0.2, true}, [](history::Sink::Level, const std::string&) {});
  ASSERT_TRUE(sink.wait_drained(std::chrono::seconds(30)));
  auto s = history::Store::open(db);
  expect_stored_as_written(*s, run);
  fs::remove_all(dir);
}

TEST(EicaldHistoryFaults, ALockedSqliteStoreDoesNotDelayTheMeasurement) {
  const fs::path dir = scratch("eicald-locked");
  const std::string db = (dir / "history.db").string();
  (void)history::Store::open(db, {.create = true});
  auto holder = history::sql::open_sqlite(db, {});
  holder->exec("BEGIN IMMEDIATE");
  std::atomic<bool> stop{false};
  daemon::Service(one_measurement(dir, db)).run(stop, [](const daemon::ServiceStatus&) {});
  const fs::path run = the_run(dir / "runs");
  ASSERT_TRUE(fs::exists(run / "result.json"));
  EXPECT_EQ(history::Spool(dir / "spool").waiting().size(), 1u);  // not taken while locked, not lost
  holder->exec("ROLLBACK");
  holder.reset();
  history::Sink sink({db, dir / "spool", 0.2, true}, [](history::Sink::Level, const std::string&) {});
  ASSERT_TRUE(sink.wait_drained(std::chrono::seconds(30)));
  auto s = history::Store::open(db);
  expect_stored_as_written(*s, run);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace eical::test
