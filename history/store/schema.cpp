#include "history/store/schema.hpp"

#include <vector>

namespace eical::history {
namespace {

struct Migration {
  int version;
  const char* what;
  std::vector<const char*> sqlite, postgresql;  // one statement each
};

// Append only: a released migration is never edited, a change is a new one.
const std::vector<Migration>& migrations() {
  static const std::vector<Migration> m = {
      // The document has a table of its own: result rows stay small and dense, so listings
      // and trends read few pages whatever the documents weigh (14 kB each for a circle).
      {1,
       "results, their figures and documents",
       {"CREATE TABLE results (id INTEGER PRIMARY KEY, machine TEXT NOT NULL, run_id TEXT NOT NULL, program TEXT NOT "
        "NULL, "
        "measured_at TEXT NOT NULL, verdict TEXT, degraded INTEGER NOT NULL, run_path TEXT NOT NULL, software_version "
        "TEXT, "
        "sensor_calibration TEXT NOT NULL, added_at TEXT NOT NULL, UNIQUE (machine, run_id))",
        "CREATE TABLE figures (result_id INTEGER NOT NULL REFERENCES results (id) ON DELETE CASCADE, name TEXT NOT "
        "NULL, "
        "value REAL, uncertainty_k2 REAL, PRIMARY KEY (result_id, name)) WITHOUT ROWID",
        "CREATE TABLE documents (result_id INTEGER PRIMARY KEY REFERENCES results (id) ON DELETE CASCADE, document "
        "TEXT NOT NULL)"},
       // COLLATE "C": text sorts and compares byte-wise, as in SQLite, whatever the server's locale.
       {"CREATE TABLE results (id BIGINT GENERATED ALWAYS AS IDENTITY PRIMARY KEY, machine TEXT COLLATE \"C\" NOT "
        "NULL, "
        "run_id TEXT COLLATE \"C\" NOT NULL, program TEXT COLLATE \"C\" NOT NULL, measured_at TEXT COLLATE \"C\" NOT "
        "NULL, "
        "verdict TEXT, degraded INTEGER NOT NULL, run_path TEXT NOT NULL, software_version TEXT, sensor_calibration "
        "TEXT NOT NULL, "
        "added_at TEXT NOT NULL, UNIQUE (machine, run_id))",
        "CREATE TABLE figures (result_id BIGINT NOT NULL REFERENCES results (id) ON DELETE CASCADE, name TEXT COLLATE "
        "\"C\" NOT NULL, "
        "value DOUBLE PRECISION, uncertainty_k2 DOUBLE PRECISION, PRIMARY KEY (result_id, name))",
        "CREATE TABLE documents (result_id BIGINT PRIMARY KEY REFERENCES results (id) ON DELETE CASCADE, document TEXT "
        "NOT NULL)"}},
      // Trend and list queries: a machine's results in time order, one figure over the fleet.
      {2,
       "indexes for the list and trend queries",
       {"CREATE INDEX results_by_machine_time ON results (machine, measured_at)",
        "CREATE INDEX results_by_time ON results (measured_at)",
        "CREATE INDEX figures_by_name ON figures (name, result_id)"},
       {"CREATE INDEX results_by_machine_time ON results (machine, measured_at)",
        "CREATE INDEX results_by_time ON results (measured_at)",
        "CREATE INDEX figures_by_name ON figures (name, result_id)"}},
  };
  return m;
}

bool schema_table_exists(sql::Connection& c) {
  const auto rows =
      c.dialect() == sql::Dialect::sqlite
          ? c.query("SELECT count(*) FROM sqlite_master WHERE type = 'table' AND name = 'eical_schema'")
          : c.query(
                "SELECT count(*) FROM pg_tables WHERE schemaname = current_schema() AND tablename = 'eical_schema'");
  return sql::to_int(rows.at(0).at(0)) > 0;
}

}  // namespace

int schema_version(sql::Connection& c) {
  if (!schema_table_exists(c)) return 0;
  const auto rows = c.query("SELECT max(version) FROM eical_schema");
  return rows.empty() || !rows[0][0] ? 0 : static_cast<int>(sql::to_int(rows[0][0]));
}

int migrate(sql::Connection& c, bool create, int target) {
  // Up to date: no write lock taken (a read-only user of a store can query it).
  if (const int now = schema_version(c); now == target) return now;
  sql::Transaction tx(c);
  // Two writers opening a new PostgreSQL store at once (collectors, eicalds): one creates
  // the schema, the other waits here and then finds it (SQLite: BEGIN IMMEDIATE does it).
  if (c.dialect() == sql::Dialect::postgresql) c.exec("SELECT pg_advisory_xact_lock(6652009271)");
  const int found = schema_version(c);
  if (found > kSchemaVersion)
    throw SchemaError("history store " + c.location() + " has schema version " + std::to_string(found) +
                      "; this eical knows versions up to " + std::to_string(kSchemaVersion) +
                      ": use the newer eical that wrote it (the store was left untouched)");
  if (found == 0 && !create)
    throw SchemaError("history store " + c.location() + ": not an eical history store (no eical_schema table)");
  if (found >= target) return found;
  if (found == 0) {
    c.exec("CREATE TABLE eical_schema (version INTEGER NOT NULL)");
    c.exec("INSERT INTO eical_schema (version) VALUES (0)");
  }
  for (const auto& m : migrations()) {
    if (m.version <= found || m.version > target) continue;
    for (const char* s : c.dialect() == sql::Dialect::sqlite ? m.sqlite : m.postgresql) c.exec(s);
    c.exec("UPDATE eical_schema SET version = $1", {static_cast<std::int64_t>(m.version)});
  }
  tx.commit();
  return found;
}

}  // namespace eical::history
