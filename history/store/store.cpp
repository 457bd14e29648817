#include "history/store/store.hpp"

#include "history/record/utc_time.hpp"
#include "history/sql/pg_connection.hpp"
#include "history/sql/sqlite_connection.hpp"
#include "history/store/schema.hpp"

#include <algorithm>
#include <ctime>

namespace eical::history {
namespace {

using sql::Value;

Value text_or_null(const std::optional<std::string>& s) { return s ? Value(*s) : Value(); }
Value number_or_null(const std::optional<double>& d) { return d ? Value(*d) : Value(); }
std::optional<std::string> optional_text(const sql::Cell& c) {
  return c ? std::optional<std::string>(*c) : std::nullopt;
}

// The WHERE clause of a filter on results aliased `r`, its parameters appended to `p`.
std::string where(const Filter& f, std::vector<Value>& p) {
  std::string w;
  auto add = [&](const char* cond, const std::string& v) {
    p.emplace_back(v);
    w += (w.empty() ? " WHERE " : " AND ") + std::string(cond) + "$" + std::to_string(p.size());
  };
  if (!f.machine.empty()) add("r.machine = ", f.machine);
  if (!f.program.empty()) add("r.program = ", f.program);
  if (!f.since.empty()) add("r.measured_at >= ", f.since);
  if (!f.until.empty()) add("r.measured_at < ", f.until);
  return w;
}

// Figures go in multi-row INSERTs of this many rows (4 parameters each): few round trips
// to a PostgreSQL server, well below both databases' parameter limits.
constexpr std::size_t kFigureRowsPerInsert = 64;

}  // namespace

std::unique_ptr<Store> Store::open(const std::string& location, const OpenOptions& options) {
  if (sql::is_postgresql_uri(location)) return std::make_unique<Store>(sql::open_postgresql(location), options);
  return std::make_unique<Store>(sql::open_sqlite(location, {.create = options.create}), options);
}

Store::Store(std::unique_ptr<sql::Connection> connection, const OpenOptions& options, int target_version)
    : c_(std::move(connection)) {
  migrate(*c_, options.create, target_version < 0 ? kSchemaVersion : target_version);
}

int Store::schema_version() { return history::schema_version(*c_); }

AddOutcome Store::insert(const Record& r) {
  const auto rows = c_->query(
      "INSERT INTO results (machine, run_id, program, measured_at, verdict, degraded, run_path, software_version, "
      "sensor_calibration, added_at) VALUES ($1, $2, $3, $4, $5, $6, $7, $8, $9, $10) "
      "ON CONFLICT (machine, run_id) DO NOTHING RETURNING id",
      {r.machine, r.run_id, r.program, r.measured_at, text_or_null(r.verdict),
       static_cast<std::int64_t>(r.degraded ? 1 : 0), r.run_path, text_or_null(r.software_version),
       r.sensor_calibration, utc_now()});
  if (rows.empty()) return AddOutcome::duplicate;
  const std::int64_t id = sql::to_int(rows[0][0]);
  c_->exec("INSERT INTO documents (result_id, document) VALUES ($1, $2)", {id, r.document});
  for (std::size_t first = 0; first < r.figures.size(); first += kFigureRowsPerInsert) {
    const std::size_t n = std::min(kFigureRowsPerInsert, r.figures.size() - first);
    std::string s = "INSERT INTO figures (result_id, name, value, uncertainty_k2) VALUES ";
    std::vector<Value> p{id};
    for (std::size_t i = 0; i < n; ++i) {
      const Figure& f = r.figures[first + i];
      const std::size_t k = p.size();
      s += (i ? ", ($1, $" : "($1, $") + std::to_string(k + 1) + ", $" + std::to_string(k + 2) + ", $" +
           std::to_string(k + 3) + ")";
      p.emplace_back(f.name);
      p.push_back(number_or_null(f.value));
      p.push_back(number_or_null(f.uncertainty_k2));
    }
    c_->exec(s, p);
  }
  return AddOutcome::added;
}

AddOutcome Store::add(const Record& r) {
  sql::Transaction tx(*c_);
  const AddOutcome o = insert(r);
  tx.commit();
  return o;
}

std::vector<AddOutcome> Store::add_many(const std::vector<Record>& records) {
  std::vector<AddOutcome> out;
  out.reserve(records.size());
  sql::Transaction tx(*c_);
  for (const auto& r : records) out.push_back(insert(r));
  tx.commit();
  return out;
}

std::vector<Summary> Store::list(const Filter& f) {
  std::vector<Value> p;
  std::string s =
      "SELECT r.machine, r.run_id, r.program, r.measured_at, r.verdict, r.degraded FROM results r" + where(f, p);
  s += f.limit ? " ORDER BY r.measured_at DESC, r.id DESC LIMIT " + std::to_string(f.limit)
               : " ORDER BY r.measured_at, r.id";
  std::vector<Summary> out;
  for (const auto& row : c_->query(s, p))
    out.push_back({sql::to_text(row[0]), sql::to_text(row[1]), sql::to_text(row[2]), sql::to_text(row[3]),
                   optional_text(row[4]), sql::to_int(row[5]) != 0});
  if (f.limit) std::reverse(out.begin(), out.end());
  return out;
}

std::vector<Record> Store::find(const std::string& run_id, const std::string& machine) {
  std::vector<Value> p{run_id};
  std::string s =
      "SELECT r.id, r.machine, r.run_id, r.program, r.measured_at, r.verdict, r.degraded, r.run_path, "
      "r.software_version, "
      "r.sensor_calibration, d.document FROM results r JOIN documents d ON d.result_id = r.id WHERE r.run_id = $1";
  if (!machine.empty()) s += " AND r.machine = $2", p.emplace_back(machine);
  s += " ORDER BY r.machine";
  std::vector<Record> out;
  for (const auto& row : c_->query(s, p)) {
    Record r;
    r.machine = sql::to_text(row[1]), r.run_id = sql::to_text(row[2]), r.program = sql::to_text(row[3]);
    r.measured_at = sql::to_text(row[4]), r.verdict = optional_text(row[5]), r.degraded = sql::to_int(row[6]) != 0;
    r.run_path = sql::to_text(row[7]), r.software_version = optional_text(row[8]),
    r.sensor_calibration = sql::to_text(row[9]);
    r.document = sql::to_text(row[10]);
    for (const auto& fr :
         c_->query("SELECT name, value, uncertainty_k2 FROM figures WHERE result_id = $1 ORDER BY name",
                   {sql::to_int(row[0])}))
      r.figures.push_back({sql::to_text(fr[0]), sql::to_optional_double(fr[1]), sql::to_optional_double(fr[2])});
    out.push_back(std::move(r));
  }
  return out;
}

std::vector<TrendPoint> Store::trend(const std::string& figure, const Filter& f) {
  std::vector<Value> p{figure};
  std::string s =
      "SELECT r.machine, r.run_id, r.measured_at, r.verdict, r.degraded, f.value, f.uncertainty_k2 "
      "FROM results r JOIN figures f ON f.result_id = r.id AND f.name = $1" +
      where(f, p);
  s += f.limit ? " ORDER BY r.measured_at DESC, r.id DESC LIMIT " + std::to_string(f.limit)
               : " ORDER BY r.measured_at, r.id";
  std::vector<TrendPoint> out;
  for (const auto& row : c_->query(s, p))
    out.push_back({sql::to_text(row[0]), sql::to_text(row[1]), sql::to_text(row[2]), optional_text(row[3]),
                   sql::to_int(row[4]) != 0, sql::to_optional_double(row[5]), sql::to_optional_double(row[6])});
  if (f.limit) std::reverse(out.begin(), out.end());
  return out;
}

std::vector<std::string> Store::figure_names(const std::string& machine) {
  const auto rows = machine.empty() ? c_->query("SELECT DISTINCT name FROM figures ORDER BY name")
                                    : c_->query(
                                          "SELECT DISTINCT f.name FROM figures f JOIN results r ON r.id = f.result_id "
                                          "WHERE r.machine = $1 ORDER BY f.name",
                                          {machine});
  std::vector<std::string> out;
  for (const auto& row : rows) out.push_back(sql::to_text(row[0]));
  return out;
}

std::vector<std::string> Store::machines() {
  std::vector<std::string> out;
  for (const auto& row : c_->query("SELECT DISTINCT machine FROM results ORDER BY machine"))
    out.push_back(sql::to_text(row[0]));
  return out;
}

std::size_t Store::count() {
  return static_cast<std::size_t>(sql::to_int(c_->query("SELECT count(*) FROM results").at(0).at(0)));
}

}  // namespace eical::history
