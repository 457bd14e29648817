#pragma once
// The calibration history: one interface over both backends (a SQLite file on the control
// PC, a PostgreSQL database for a shop's fleet). The same SQL runs on both, so both give
// the same answers. A result is keyed by (machine, run id): adding it again is a no-op.
#include "history/record/record.hpp"
#include "history/sql/connection.hpp"

#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace eical::history {

struct OpenOptions {
  bool create = false;  // create a missing SQLite file / the schema in an empty database
};

enum class AddOutcome { added, duplicate };

// Which results: every field empty/0 = no restriction. Times compare as RFC 3339 UTC text,
// so "2026-11" or "2026-11-12" work as prefixes for since/until.
struct Filter {
  std::string machine = {}, program = {};
  std::string since = {}, until = {};  // measured_at >= since, measured_at < until (until: exclusive)
  std::size_t limit = 0;               // the newest `limit`, shown oldest first
};

struct TrendPoint {
  std::string machine, run_id, measured_at;
  std::optional<std::string> verdict;
  bool degraded = false;
  std::optional<double> value, uncertainty_k2;
};

class Store {
 public:
  // "postgresql://..." → PostgreSQL, anything else is a SQLite file path. Throws
  // sql::SqlError (cannot open: the cause) or SchemaError (newer schema, not a store).
  static std::unique_ptr<Store> open(const std::string& location, const OpenOptions& options = {});
  explicit Store(std::unique_ptr<sql::Connection> connection, const OpenOptions& options = {}, int target_version = -1);

  // One transaction per call; add_many keeps a backlog fast (a commit per batch).
  AddOutcome add(const Record& r);
  std::vector<AddOutcome> add_many(const std::vector<Record>& records);

  std::vector<Summary> list(const Filter& f);
  // The results with this run id (of `machine` when given), figures and document included.
  std::vector<Record> find(const std::string& run_id, const std::string& machine = "");
  // One figure over time, oldest first (machine and program of the filter apply).
  std::vector<TrendPoint> trend(const std::string& figure, const Filter& f);
  // The figure names stored for a machine (all machines when empty), for messages.
  std::vector<std::string> figure_names(const std::string& machine);
  std::vector<std::string> machines();
  std::size_t count();

  int schema_version();
  [[nodiscard]] const std::string& location() const { return c_->location(); }
  [[nodiscard]] sql::Connection& connection() { return *c_; }

 private:
  AddOutcome insert(const Record& r);
  std::unique_ptr<sql::Connection> c_;
};

}  // namespace eical::history
