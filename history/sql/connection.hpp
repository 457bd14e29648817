#pragma once
// The one SQL interface the history store talks through, with two backends (SQLite on the
// control PC, PostgreSQL through libpq for a fleet). Statements are written once with
// PostgreSQL's numbered placeholders ($1, $2, ...); the SQLite backend binds them as ?NNN.
// Values travel as text in result rows (doubles printed with 17 digits read back exactly),
// so both backends give the store identical answers.
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <variant>
#include <vector>

namespace eical::history::sql {

// Every failure of a backend: the message names the store (without a password) and the
// database's own reason, e.g. "history store /var/lib/eical/history.db: database is locked".
class SqlError : public std::runtime_error {
 public:
  explicit SqlError(const std::string& what) : std::runtime_error(what) {}
};

enum class Dialect { sqlite, postgresql };

using Value = std::variant<std::monostate, std::int64_t, double, std::string>;  // monostate = NULL
using Cell = std::optional<std::string>;                                        // nullopt = NULL
using Row = std::vector<Cell>;
using Rows = std::vector<Row>;

class Connection {
 public:
  virtual ~Connection() = default;
  [[nodiscard]] virtual Dialect dialect() const = 0;
  // The store as messages name it (a PostgreSQL URI without its password).
  [[nodiscard]] virtual const std::string& location() const = 0;
  // Runs one statement; the rows it returns (none for most writes).
  virtual Rows query(const std::string& sql, const std::vector<Value>& params = {}) = 0;
  void exec(const std::string& sql, const std::vector<Value>& params = {}) { (void)query(sql, params); }
};

// BEGIN (SQLite: IMMEDIATE, so a writer takes the lock at once and never fails half-way on
// an upgrade) ... commit(); a transaction not committed is rolled back by the destructor.
class Transaction {
 public:
  explicit Transaction(Connection& c);
  ~Transaction();
  Transaction(const Transaction&) = delete;
  Transaction& operator=(const Transaction&) = delete;
  void commit();

 private:
  Connection& c_;
  bool done_ = false;
};

// Cell conversions (SqlError when a cell does not hold what the schema says it does).
double to_double(const Cell& c);
std::int64_t to_int(const Cell& c);
std::optional<double> to_optional_double(const Cell& c);
std::string to_text(const Cell& c);  // NULL → ""

}  // namespace eical::history::sql
