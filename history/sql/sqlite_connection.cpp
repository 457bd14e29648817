#include "history/sql/sqlite_connection.hpp"

#include <sqlite3.h>

#include <cctype>
#include <cstdio>
#include <unordered_map>

namespace eical::history::sql {
namespace {

// "$12" → "?12": the statements are written once with PostgreSQL's placeholders.
std::string sqlite_placeholders(const std::string& sql) {
  std::string out = sql;
  for (std::size_t i = 0; i + 1 < out.size(); ++i)
    if (out[i] == '$' && std::isdigit(static_cast<unsigned char>(out[i + 1]))) out[i] = '?';
  return out;
}

class SqliteConnection final : public Connection {
 public:
  SqliteConnection(const std::filesystem::path& file, const SqliteOptions& o) : location_(file.string()) {
    std::error_code ec;
    const bool exists = std::filesystem::exists(file, ec);
    if (!exists && !o.create) fail("no history store there (eicald or `eical history add` creates one)");
    if (!exists) {
      const auto parent = file.parent_path().empty() ? std::filesystem::path(".") : file.parent_path();
      if (!std::filesystem::is_directory(parent, ec)) fail("directory " + parent.string() + " does not exist");
    }
    const int flags = SQLITE_OPEN_READWRITE | (o.create ? SQLITE_OPEN_CREATE : 0) | SQLITE_OPEN_NOMUTEX;
    if (sqlite3_open_v2(location_.c_str(), &db_, flags, nullptr) != SQLITE_OK) {
      const std::string why = db_ ? sqlite3_errmsg(db_) : "out of memory";
      sqlite3_close(db_);
      db_ = nullptr;
      fail(why);
    }
    sqlite3_extended_result_codes(db_, 1);
    sqlite3_busy_timeout(db_, o.busy_timeout_ms);
    // The first statement reads the file: a corrupt or foreign file fails here ("file is
    // not a database"), before anything is written.
    try {
      exec("PRAGMA journal_mode = WAL");
      exec("PRAGMA synchronous = FULL");
      exec("PRAGMA foreign_keys = ON");
    } catch (...) {
      close();
      throw;
    }
  }

  ~SqliteConnection() override { close(); }

  [[nodiscard]] Dialect dialect() const override { return Dialect::sqlite; }
  [[nodiscard]] const std::string& location() const override { return location_; }

  Rows query(const std::string& sql, const std::vector<Value>& params) override {
    sqlite3_stmt* st = prepare(sql);
    for (std::size_t i = 0; i < params.size(); ++i) bind(st, static_cast<int>(i + 1), params[i]);
    Rows rows;
    for (;;) {
      const int rc = sqlite3_step(st);
      if (rc == SQLITE_DONE) break;
      if (rc != SQLITE_ROW) {
        const std::string why = sqlite3_errmsg(db_);
        sqlite3_reset(st);
        sqlite3_clear_bindings(st);
        fail(why);
      }
      const int n = sqlite3_column_count(st);
      Row row(static_cast<std::size_t>(n));
      for (int c = 0; c < n; ++c) row[static_cast<std::size_t>(c)] = cell(st, c);
      rows.push_back(std::move(row));
    }
    sqlite3_reset(st);
    sqlite3_clear_bindings(st);
    return rows;
  }

 private:
  void close() {
    for (auto& [sql, st] : cache_) sqlite3_finalize(st);
    cache_.clear();
    sqlite3_close(db_);
    db_ = nullptr;
  }

  [[noreturn]] void fail(const std::string& why) const { throw SqlError("history store " + location_ + ": " + why); }

  sqlite3_stmt* prepare(const std::string& sql) {
    if (auto it = cache_.find(sql); it != cache_.end()) return it->second;
    sqlite3_stmt* st = nullptr;
    const std::string text = sqlite_placeholders(sql);
    if (sqlite3_prepare_v3(db_, text.c_str(), static_cast<int>(text.size()), SQLITE_PREPARE_PERSISTENT, &st, nullptr) !=
        SQLITE_OK)
      fail(sqlite3_errmsg(db_));
    cache_.emplace(sql, st);
    return st;
  }

  void bind(sqlite3_stmt* st, int i, const Value& v) {
    int rc = SQLITE_OK;
    if (std::holds_alternative<std::monostate>(v))
      rc = sqlite3_bind_null(st, i);
    else if (const auto* n = std::get_if<std::int64_t>(&v))
      rc = sqlite3_bind_int64(st, i, *n);
    else if (const auto* d = std::get_if<double>(&v))
      rc = sqlite3_bind_double(st, i, *d);
    else {
      const auto& s = std::get<std::string>(v);
      rc = sqlite3_bind_text(st, i, s.data(), static_cast<int>(s.size()), SQLITE_TRANSIENT);
    }
    if (rc != SQLITE_OK) fail(sqlite3_errmsg(db_));
  }

  static Cell cell(sqlite3_stmt* st, int c) {
    switch (sqlite3_column_type(st, c)) {
      case SQLITE_NULL: return std::nullopt;
      case SQLITE_INTEGER: return std::to_string(sqlite3_column_int64(st, c));
      case SQLITE_FLOAT: {
        char b[40];
        std::snprintf(b, sizeof b, "%.17g", sqlite3_column_double(st, c));
        return std::string(b);
      }
      default: {
        const auto* p = reinterpret_cast<const char*>(sqlite3_column_text(st, c));
        return std::string(p ? p : "", static_cast<std::size_t>(sqlite3_column_bytes(st, c)));
      }
    }
  }

  std::string location_;
  sqlite3* db_ = nullptr;
  std::unordered_map<std::string, sqlite3_stmt*> cache_;
};

}  // namespace

std::unique_ptr<Connection> open_sqlite(const std::filesystem::path& file, const SqliteOptions& options) {
  return std::make_unique<SqliteConnection>(file, options);
}

}  // namespace eical::history::sql
