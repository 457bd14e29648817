// The history sink's threads (also under ThreadSanitizer, label "threads"): results handed
// over from several threads at once while the store is locked by another connection and
// then released all enter it once, and the sink's counters and messages stay consistent.
#include "history/record/result_record.hpp"
#include "history/spool/sink.hpp"
#include "history/sql/sqlite_connection.hpp"
#include "history/store/store.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <atomic>
#include <chrono>
#include <filesystem>
#include <random>
#include <thread>
#include <vector>

namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

eical::history::Record record(int thread, int i) {
  const nlohmann::json doc = {{"format", "eical-result/1"},
                              {"run_id", "t" + std::to_string(thread) + "-" + std::to_string(i)},
                              {"program", "step"},
                              {"quality", {{"degraded", false}, {"verdict", "ok"}}},
                              {"uncertainty_k2", {{"step.end_position_error_um", 0.3}}},
                              {"step", {{"end_position_error_um", 0.1 * i}, {"overshoot_um", 1.0}}}};
  return eical::history::record_from_result(doc, {"maho-1", "2026-11-12T09:11:00Z", "/runs", std::nullopt, ""});
}

TEST(HistorySinkThreads, ConcurrentSubmitsWhileTheStoreIsLockedAllEnterOnce) {
  const fs::path dir = fs::temp_directory_path() / ("eical-sink-threads-" + std::to_string(std::random_device{}()));
  fs::create_directories(dir);
  const std::string db = (dir / "history.db").string();
  (void)eical::history::Store::open(db, {.create = true});
  auto holder = eical::history::sql::open_sqlite(db, {});
  holder->exec("BEGIN IMMEDIATE");
  std::atomic<int> messages{0};
  {
    eical::history::Sink sink({db, dir / "spool", 0.05, true},
                              [&](eical::history::Sink::Level, const std::string&) { ++messages; });
    constexpr int kThreads = 4, kEach = 25;
    std::vector<std::thread> producers;
    for (int t = 0; t < kThreads; ++t)
      producers.emplace_back([&, t] {
        for (int i = 0; i < kEach; ++i) {
          sink.submit(record(t, i));
          (void)sink.problem();  // read while the writer thread sets it
          (void)sink.counts();
        }
      });
    for (auto& p : producers) p.join();
    // The lock outlasts SQLite's busy timeout: the writer reports it, the results wait.
    for (auto end = std::chrono::steady_clock::now() + 30s;
         sink.problem().empty() && std::chrono::steady_clock::now() < end;)
      std::this_thread::sleep_for(20ms);
    EXPECT_NE(sink.problem().find("database is locked"), std::string::npos) << sink.problem();
    EXPECT_GT(sink.waiting(), 0u);
    holder->exec("ROLLBACK");
    sink.retry_now();
    ASSERT_TRUE(sink.wait_drained(60s));
    EXPECT_EQ(sink.counts().stored, static_cast<std::uint64_t>(kThreads * kEach));
    EXPECT_EQ(sink.counts().duplicates, 0u);
    EXPECT_TRUE(sink.problem().empty());
  }
  EXPECT_EQ(eical::history::Store::open(db)->count(), 100u);
  EXPECT_GE(messages.load(), 2);  // the lock named, and its end
  fs::remove_all(dir);
}

}  // namespace
