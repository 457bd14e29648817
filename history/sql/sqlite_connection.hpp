#pragma once
// The SQLite backend: a file on the control PC. WAL journal (a reader never blocks the
// writer), synchronous=FULL (a result reported stored survives a power cut), a busy timeout
// so a store locked by another process waits a little and then fails with SQLite's reason.
#include "history/sql/connection.hpp"

#include <filesystem>
#include <memory>

namespace eical::history::sql {

struct SqliteOptions {
  bool create = false;         // create the file when missing (its directory must exist)
  int busy_timeout_ms = 2000;  // wait this long for a lock held by another process
};

// Throws SqlError naming the file and the cause: no such file, missing directory, not a
// database (a corrupt or foreign file), locked, read-only.
std::unique_ptr<Connection> open_sqlite(const std::filesystem::path& file, const SqliteOptions& options);

}  // namespace eical::history::sql
