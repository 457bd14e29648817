// Nothing lost on the way into the store: results handed to the sink are spooled on disk
// and enter the store; when it is missing, locked, corrupt, of a newer schema, or the
// database goes away, they wait in the spool with one message naming the cause, and enter
// the store when it is back — also after a restart of the process.
#include "history/spool/sink.hpp"
#include "history/record/result_record.hpp"
#include "history/sql/sqlite_connection.hpp"
#include "history/store/store.hpp"
#include "history_support.hpp"

#include <chrono>
#include <fstream>
#include <mutex>

namespace eical::test {
namespace {

using namespace std::chrono_literals;
using history::Sink;

history::Record sink_record(const std::string& run) {
  return history::record_from_result(circle_result(run),
                                     {"maho-1", "2026-11-12T09:11:00Z", "/runs/" + run, std::nullopt, ""});
}

// Collects the sink's messages.
struct Messages {
  std::mutex mu;
  std::vector<std::pair<Sink::Level, std::string>> lines;
  Sink::Log log() {
    return [this](Sink::Level l, const std::string& m) {
      std::lock_guard lk(mu);
      lines.emplace_back(l, m);
    };
  }
  std::string errors() {
    std::lock_guard lk(mu);
    std::string out;
    for (const auto& [l, m] : lines)
      if (l == Sink::Level::error) out += m + "\n";
    return out;
  }
};

std::size_t stored(const std::string& location) { return history::Store::open(location)->count(); }

// Until `pred` or 20 s.
template <class P>
bool eventually(P pred) {
  for (auto end = std::chrono::steady_clock::now() + 20s; std::chrono::steady_clock::now() < end;
       std::this_thread::sleep_for(20ms))
    if (pred()) return true;
  return pred();
}

class SinkTest : public ::testing::TestWithParam<Backend> {
 protected:
  void SetUp() override { dir_ = scratch("sink"), location_ = fresh_store(GetParam(), dir_); }
  void TearDown() override {
    if (GetParam() == Backend::postgresql) pg();  // running again for the next test
    fs::remove_all(dir_);
  }
  history::SinkConfig config() { return {location_, dir_ / "spool", 0.2, true}; }
  fs::path dir_;
  std::string location_;
};

TEST_P(SinkTest, ResultsEnterTheStoreAndLeaveTheSpool) {
  Messages msg;
  {
    Sink sink(config(), msg.log());
    sink.submit(sink_record("a"));
    sink.submit(sink_record("b"));
    ASSERT_TRUE(sink.wait_drained(20s)) << msg.errors();
    EXPECT_EQ(sink.counts().stored, 2u);
    EXPECT_TRUE(sink.problem().empty());
  }
  EXPECT_EQ(stored(location_), 2u);
  EXPECT_TRUE(history::Spool(dir_ / "spool").waiting().empty());
  EXPECT_EQ(msg.errors(), "");
}

TEST_P(SinkTest, AStoreOfANewerSchemaKeepsResultsSpooledAndSaysWhy) {
  history::Store::open(location_, {.create = true})->connection().exec("UPDATE eical_schema SET version = 99");
  Messages msg;
  Sink sink(config(), msg.log());
  sink.submit(sink_record("a"));
  // The problem is set before its message is logged: wait for both.
  ASSERT_TRUE(eventually([&] {
    return !sink.problem().empty() && msg.errors().find("results wait in") != std::string::npos;
  })) << msg.errors();
  EXPECT_NE(sink.problem().find("schema version 99"), std::string::npos) << sink.problem();
  EXPECT_NE(msg.errors().find("1 results wait in " + (dir_ / "spool").string()), std::string::npos) << msg.errors();
  EXPECT_EQ(history::Spool(dir_ / "spool").waiting().size(), 1u);
  EXPECT_EQ(sink.waiting(), 1u);
}

INSTANTIATE_TEST_SUITE_P(Backends, SinkTest, ::testing::Values(Backend::sqlite, Backend::postgresql), backend_name);

TEST(SinkPostgresql, ADatabaseThatGoesAwayGetsTheResultsWhenItIsBack) {
  const fs::path dir = scratch("pg-away");
  const std::string location = fresh_store(Backend::postgresql, dir);
  Messages msg;
  {
    Sink sink({location, dir / "spool", 0.2, true}, msg.log());
    sink.submit(sink_record("before"));
    ASSERT_TRUE(sink.wait_drained(20s)) << msg.errors();
    pg().stop();  // the database goes away
    sink.submit(sink_record("while-away-1"));
    sink.submit(sink_record("while-away-2"));
    ASSERT_TRUE(eventually([&] { return !sink.problem().empty(); }));
    EXPECT_NE(sink.problem().find("history store postgresql://"), std::string::npos) << sink.problem();
    EXPECT_EQ(history::Spool(dir / "spool").waiting().size(), 2u);
    pg().start();  // back
    ASSERT_TRUE(sink.wait_drained(30s)) << msg.errors();
    EXPECT_TRUE(sink.problem().empty());
  }
  auto s = history::Store::open(location);
  EXPECT_EQ(s->count(), 3u);
  EXPECT_EQ(s->find("while-away-2").size(), 1u);
  std::lock_guard lk(msg.mu);
  ASSERT_FALSE(msg.lines.empty());
  EXPECT_EQ(msg.lines.back().first, Sink::Level::info);
  EXPECT_NE(msg.lines.back().second.find("taking results again"), std::string::npos);
  fs::remove_all(dir);
}

TEST(SinkSqlite, ALockedStoreGetsTheResultsWhenTheLockIsGone) {
  const fs::path dir = scratch("locked");
  const std::string location = (dir / "history.db").string();
  (void)history::Store::open(location, {.create = true});
  auto holder = history::sql::open_sqlite(location, {});
  holder->exec("BEGIN IMMEDIATE");  // another process writing and not letting go
  Messages msg;
  Sink sink({location, dir / "spool", 0.2, true}, msg.log());
  sink.submit(sink_record("a"));
  ASSERT_TRUE(eventually([&] { return !sink.problem().empty(); }));
  EXPECT_NE(sink.problem().find("database is locked"), std::string::npos) << sink.problem();
  EXPECT_NE(sink.problem().find(location), std::string::npos) << sink.problem();
  holder->exec("ROLLBACK");
  ASSERT_TRUE(sink.wait_drained(30s)) << msg.errors();
  EXPECT_EQ(stored(location), 1u);
  fs::remove_all(dir);
}

TEST(SinkSqlite, AMissingOrCorruptStoreGetsTheResultsWhenItIsThere) {
  const fs::path dir = scratch("missing");
  const std::string location = (dir / "mnt" / "history.db").string();  // a mount that is not there
  Messages msg;
  Sink sink({location, dir / "spool", 0.2, true}, msg.log());
  sink.submit(sink_record("a"));
  ASSERT_TRUE(eventually([&] { return sink.problem().find("does not exist") != std::string::npos; })) << sink.problem();
  // The directory comes, but with a corrupt file in it.
  fs::create_directories(dir / "mnt");
  {
    std::ofstream os(location, std::ios::binary);
    os << std::string(8192, 'x');
  }
  ASSERT_TRUE(eventually([&] { return sink.problem().find("not a database") != std::string::npos; })) << sink.problem();
  EXPECT_EQ(sink.waiting(), 1u);
  fs::rename(location, location + ".corrupt");  // what the message tells the user to do
  sink.retry_now();
  ASSERT_TRUE(sink.wait_drained(30s)) << msg.errors();
  EXPECT_EQ(stored(location), 1u);
  const auto errors = msg.errors();
  EXPECT_NE(errors.find("does not exist"), std::string::npos) << errors;
  EXPECT_NE(errors.find("not a database"), std::string::npos) << errors;
  fs::remove_all(dir);
}

TEST(SinkSqlite, SpooledResultsOfAnEarlierProcessEnterTheStoreAtStart) {
  const fs::path dir = scratch("restart");
  const std::string location = (dir / "db" / "history.db").string();
  {
    Messages msg;
    Sink sink({location, dir / "spool", 0.2, true}, msg.log());  // store directory missing
    sink.submit(sink_record("a"));
    sink.submit(sink_record("b"));
    ASSERT_TRUE(eventually([&] { return !sink.problem().empty(); }));
  }  // the process ends with two results spooled
  EXPECT_EQ(history::Spool(dir / "spool").waiting().size(), 2u);
  fs::create_directories(dir / "db");
  Messages msg;
  Sink sink({location, dir / "spool", 0.2, true}, msg.log());
  ASSERT_TRUE(sink.wait_drained(20s)) << msg.errors();
  EXPECT_EQ(stored(location), 2u);
  EXPECT_EQ(sink.counts().stored, 2u);
  fs::remove_all(dir);
}

TEST(SinkSqlite, AnUnreadableSpoolFileIsSetAsideAndTheOthersGoIn) {
  const fs::path dir = scratch("bad-spool");
  fs::create_directories(dir / "spool");
  {
    std::ofstream os(dir / "spool" / "00000000000000000001-1-0.json");
    os << "{\"format\": \"eical-history-spool/1\", \"record\": {\"machine\": 3}}";
  }
  Messages msg;
  Sink sink({(dir / "history.db").string(), dir / "spool", 0.2, true}, msg.log());
  sink.submit(sink_record("good"));
  ASSERT_TRUE(sink.wait_drained(20s)) << msg.errors();
  EXPECT_EQ(sink.counts().stored, 1u);
  EXPECT_EQ(sink.counts().set_aside, 1u);
  EXPECT_TRUE(fs::exists(dir / "spool" / "bad" / "00000000000000000001-1-0.json"));
  EXPECT_NE(msg.errors().find("set aside"), std::string::npos) << msg.errors();
  fs::remove_all(dir);
}

TEST(SinkSqlite, WhenEvenTheSpoolCannotBeWrittenTheResultIsHeldInMemory) {
  const fs::path dir = scratch("no-spool");
  { std::ofstream os(dir / "spool"); }  // a file where the spool directory should be
  Messages msg;
  Sink sink({(dir / "history.db").string(), dir / "spool", 0.2, true}, msg.log());
  sink.submit(sink_record("a"));
  ASSERT_TRUE(sink.wait_drained(20s)) << msg.errors();
  EXPECT_EQ(sink.counts().stored, 1u);
  EXPECT_NE(msg.errors().find("cannot spool result a"), std::string::npos) << msg.errors();
  fs::remove_all(dir);
}

}  // namespace
}  // namespace eical::test
