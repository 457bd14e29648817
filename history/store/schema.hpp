#pragma once
// The history store's schema, the same tables in SQLite and PostgreSQL, and its versions.
// Opening a store brings it to kSchemaVersion in one transaction (migrations in order); a
// store written by a newer eical is refused and left untouched.
//
//   eical_schema (version)                                   one row
//   results (id, machine, run_id, program, measured_at, verdict, degraded, run_path,
//            software_version, sensor_calibration, added_at)
//            UNIQUE (machine, run_id): a result is keyed by its machine and run id
//   figures (result_id → results.id, name "<section>.<key>", value, uncertainty_k2)
//            PRIMARY KEY (result_id, name); value/uncertainty NULL when not determined/given
//   documents (result_id → results.id, document): the eical-result/1 JSON
#include "history/sql/connection.hpp"

#include <stdexcept>
#include <string>

namespace eical::history {

inline constexpr int kSchemaVersion = 2;

// A store this eical cannot use as it is (newer schema, not an eical store).
class SchemaError : public std::runtime_error {
 public:
  explicit SchemaError(const std::string& what) : std::runtime_error(what) {}
};

// Creates (when allowed) or upgrades the store up to `target` (tests use an older target
// to build a store as an earlier eical left it). Returns the version found before.
// Throws SchemaError for a newer store or, when !create, a database without the schema.
int migrate(sql::Connection& c, bool create, int target = kSchemaVersion);

// The version stored, 0 when the schema table does not exist.
int schema_version(sql::Connection& c);

}  // namespace eical::history
