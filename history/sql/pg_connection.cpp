#include "history/sql/pg_connection.hpp"

#include <libpq-fe.h>

#include <cstdio>
#include <unordered_map>

namespace eical::history::sql {

bool is_postgresql_uri(const std::string& location) {
  return location.rfind("postgresql://", 0) == 0 || location.rfind("postgres://", 0) == 0;
}

std::string redact_uri(const std::string& uri) {
  const auto scheme = uri.find("://");
  if (scheme == std::string::npos) return uri;
  const auto at = uri.find('@', scheme + 3);
  const auto slash = uri.find('/', scheme + 3);
  if (at == std::string::npos || (slash != std::string::npos && slash < at)) return uri;
  const auto colon = uri.find(':', scheme + 3);
  if (colon == std::string::npos || colon > at) return uri;
  return uri.substr(0, colon + 1) + "***" + uri.substr(at);
}

namespace {

// libpq's messages end in a newline and may continue with DETAIL lines: the first line.
std::string first_line(const char* text) {
  std::string s = text ? text : "";
  if (const auto nl = s.find('\n'); nl != std::string::npos) s.resize(nl);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\r')) s.pop_back();
  return s.empty() ? "unknown error" : s;
}

void ignore_notice(void*, const char*) {}  // "relation already exists, skipping" and the like

class PgConnection final : public Connection {
 public:
  explicit PgConnection(const std::string& uri) : location_(redact_uri(uri)) {
    // connect_timeout first: a value in the URI itself overrides it (expand_dbname).
    const char* keys[] = {"connect_timeout", "application_name", "dbname", nullptr};
    const char* values[] = {"5", "eical", uri.c_str(), nullptr};
    conn_ = PQconnectdbParams(keys, values, 1);
    if (!conn_ || PQstatus(conn_) != CONNECTION_OK) {
      const std::string why = conn_ ? first_line(PQerrorMessage(conn_)) : "out of memory";
      PQfinish(conn_);
      conn_ = nullptr;
      fail(why);
    }
    PQsetNoticeProcessor(conn_, ignore_notice, nullptr);
  }

  ~PgConnection() override { PQfinish(conn_); }

  [[nodiscard]] Dialect dialect() const override { return Dialect::postgresql; }
  [[nodiscard]] const std::string& location() const override { return location_; }

  Rows query(const std::string& sql, const std::vector<Value>& params) override {
    const std::string& name = prepare(sql, static_cast<int>(params.size()));
    std::vector<std::string> text(params.size());
    std::vector<const char*> ptrs(params.size(), nullptr);
    for (std::size_t i = 0; i < params.size(); ++i) {
      const Value& v = params[i];
      if (std::holds_alternative<std::monostate>(v)) continue;
      if (const auto* n = std::get_if<std::int64_t>(&v))
        text[i] = std::to_string(*n);
      else if (const auto* d = std::get_if<double>(&v)) {
        char b[40];
        std::snprintf(b, sizeof b, "%.17g", *d);
        text[i] = b;
      } else
        text[i] = std::get<std::string>(v);
      ptrs[i] = text[i].c_str();
    }
    PGresult* r =
        PQexecPrepared(conn_, name.c_str(), static_cast<int>(params.size()), ptrs.data(), nullptr, nullptr, 0);
    check(r);
    Rows rows;
    const int n = PQntuples(r), m = PQnfields(r);
    rows.reserve(static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i) {
      Row row(static_cast<std::size_t>(m));
      for (int c = 0; c < m; ++c)
        if (!PQgetisnull(r, i, c))
          row[static_cast<std::size_t>(c)] =
              std::string(PQgetvalue(r, i, c), static_cast<std::size_t>(PQgetlength(r, i, c)));
      rows.push_back(std::move(row));
    }
    PQclear(r);
    return rows;
  }

 private:
  [[noreturn]] void fail(const std::string& why) const { throw SqlError("history store " + location_ + ": " + why); }

  // A failed result: the server's message; a broken connection says so (the caller drops
  // this connection and opens a new one when it retries).
  void check(PGresult* r) {
    const auto st = r ? PQresultStatus(r) : PGRES_FATAL_ERROR;
    if (st == PGRES_COMMAND_OK || st == PGRES_TUPLES_OK) return;
    std::string why = first_line(r ? PQresultErrorMessage(r) : PQerrorMessage(conn_));
    PQclear(r);
    if (PQstatus(conn_) != CONNECTION_OK) why = "connection lost: " + why;
    fail(why);
  }

  const std::string& prepare(const std::string& sql, int nparams) {
    if (auto it = names_.find(sql); it != names_.end()) return it->second;
    const std::string name = "eical_" + std::to_string(names_.size() + 1);
    PGresult* r = PQprepare(conn_, name.c_str(), sql.c_str(), nparams, nullptr);
    check(r);
    PQclear(r);
    return names_.emplace(sql, name).first->second;
  }

  std::string location_;
  PGconn* conn_ = nullptr;
  std::unordered_map<std::string, std::string> names_;  // SQL → prepared statement name
};

}  // namespace

std::unique_ptr<Connection> open_postgresql(const std::string& uri) { return std::make_unique<PgConnection>(uri); }

}  // namespace eical::history::sql
