#pragma once
// Results on their way into the history store, with nothing lost: submit() writes the
// result to the on-disk spool (durable) and returns at once; a writer thread of the sink's
// own moves spooled results into the store. A store that is missing, locked, corrupt,
// of a newer schema, or a database that went away leaves the results in the spool, says
// why (one message per new cause, through `log`), and is tried again every retry_s; the
// results enter the store when it is back, in the order they were measured. Spooled
// results of an earlier process (crash, restart) are moved in at start.
// Used by eicald (one call per evaluated result, on its evaluation thread) and by
// `eical collect`.
#include "history/record/record.hpp"
#include "history/spool/spool.hpp"

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <filesystem>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

namespace eical::history {

class Store;

struct SinkConfig {
  std::string location;  // SQLite file or postgresql:// URI
  std::filesystem::path spool_dir;
  double retry_s = 30.0;  // a failed store is tried again after this
  bool create = true;     // create the store (file / schema) when missing
};

class Sink {
 public:
  enum class Level { info, error };
  using Log = std::function<void(Level, const std::string&)>;

  Sink(SinkConfig config, Log log);
  ~Sink();  // one last attempt (unless the store is known away); what waits stays spooled
  Sink(const Sink&) = delete;
  Sink& operator=(const Sink&) = delete;

  // Never blocks on the store. When even the spool cannot be written (disk full), the
  // record is kept in memory and the cause logged; it still goes to the store when it can.
  void submit(const Record& r);

  // Empty while the store takes every result; else why results wait.
  [[nodiscard]] std::string problem() const;
  [[nodiscard]] std::size_t waiting() const;  // spooled or held in memory
  struct Counts {
    std::uint64_t stored = 0, duplicates = 0, set_aside = 0;
  };
  [[nodiscard]] Counts counts() const;
  // Blocks until nothing waits or `timeout` passes (tests; the collector before it exits).
  bool wait_drained(std::chrono::milliseconds timeout);
  void retry_now();  // skips the rest of the retry wait

 private:
  void writer();
  bool flush();  // true when everything waiting went in
  void set_problem(const std::string& p);

  SinkConfig config_;
  Log log_;
  Spool spool_;
  mutable std::mutex mu_;
  std::condition_variable cv_, drained_;
  std::deque<std::pair<std::filesystem::path, Record>> memory_;  // not spooled (spool failed)
  std::string problem_;
  Counts counts_;
  std::size_t waiting_ = 0;
  bool wake_ = true, stop_ = false;
  std::unique_ptr<Store> store_;  // the writer thread's connection (only it touches it)
  std::thread thread_;
};

}  // namespace eical::history
