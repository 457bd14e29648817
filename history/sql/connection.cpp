#include "history/sql/connection.hpp"

#include <cerrno>
#include <cstdlib>

namespace eical::history::sql {

Transaction::Transaction(Connection& c) : c_(c) {
  c_.exec(c_.dialect() == Dialect::sqlite ? "BEGIN IMMEDIATE" : "BEGIN");
}

Transaction::~Transaction() {
  if (done_) return;
  try {
    c_.exec("ROLLBACK");
  } catch (const SqlError&) {
    // The connection is gone: the server rolls the transaction back itself.
  }
}

void Transaction::commit() {
  c_.exec("COMMIT");
  done_ = true;
}

double to_double(const Cell& c) {
  if (!c) throw SqlError("history store: NULL where a number was expected");
  char* end = nullptr;
  errno = 0;
  const double v = std::strtod(c->c_str(), &end);
  if (end == c->c_str() || *end != '\0') throw SqlError("history store: '" + *c + "' is not a number");
  return v;
}

std::int64_t to_int(const Cell& c) {
  if (!c) throw SqlError("history store: NULL where an integer was expected");
  char* end = nullptr;
  const long long v = std::strtoll(c->c_str(), &end, 10);
  if (end == c->c_str() || *end != '\0') throw SqlError("history store: '" + *c + "' is not an integer");
  return v;
}

std::optional<double> to_optional_double(const Cell& c) {
  if (!c) return std::nullopt;
  return to_double(c);
}

std::string to_text(const Cell& c) { return c ? *c : std::string(); }

}  // namespace eical::history::sql
