#include "drivers/config/strict_toml.hpp"

#include "dsp/core/error.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

namespace eical::drivers {
namespace {

std::string type_name(const toml::node& n) {
  switch (n.type()) {
    case toml::node_type::table: return "table";
    case toml::node_type::array: return "array";
    case toml::node_type::string: return "string";
    case toml::node_type::integer: return "integer";
    case toml::node_type::floating_point: return "float";
    case toml::node_type::boolean: return "boolean";
    case toml::node_type::date: return "date";
    case toml::node_type::time: return "time";
    case toml::node_type::date_time: return "date-time";
    default: return "nothing";
  }
}

std::string join(std::string_view section, std::string_view key) {
  return section.empty() ? std::string(key) : std::string(section) + "." + std::string(key);
}

}  // namespace

StrictTable::StrictTable(const toml::table& table, std::string file, std::string section)
    : table_(&table), file_(std::move(file)), section_(std::move(section)) {}

toml::table StrictTable::parse_file(const std::string& path) {
  try {
    return toml::parse_file(path);
  } catch (const toml::parse_error& e) {
    std::ostringstream os;
    os << path << ":" << e.source().begin.line << ":" << e.source().begin.column << ": " << e.description();
    throw dsp::InputError(os.str());
  }
}

std::string StrictTable::where(std::string_view key) const {
  std::ostringstream os;
  os << file_;
  const toml::node* n = table_->get(key);
  const auto line = n ? n->source().begin.line : table_->source().begin.line;
  if (line > 0) os << ":" << line;
  os << ": " << join(section_, key);
  return os.str();
}

void StrictTable::fail(std::string_view key, const std::string& reason) const {
  throw dsp::InputError(where(key) + ": " + reason);
}

bool StrictTable::has(std::string_view key) const { return table_->contains(key); }

const toml::node* StrictTable::get(std::string_view key, bool required) {
  used_.emplace(key);
  const toml::node* n = table_->get(key);
  if (!n && required) fail(key, "required key is missing");
  return n;
}

double StrictTable::number(std::string_view key) {
  const toml::node* n = get(key, true);
  double v;
  if (auto i = n->value_exact<std::int64_t>())
    v = static_cast<double>(*i);
  else if (auto f = n->value_exact<double>())
    v = *f;
  else
    fail(key, "expected a number, got " + type_name(*n));
  if (!std::isfinite(v)) fail(key, "expected a finite number");
  return v;
}

double StrictTable::number(std::string_view key, double fallback) {
  return has(key) ? number(key) : (used_.emplace(key), fallback);
}

std::int64_t StrictTable::integer(std::string_view key) {
  const toml::node* n = get(key, true);
  auto i = n->value_exact<std::int64_t>();
  if (!i) fail(key, "expected an integer, got " + type_name(*n));
  return *i;
}

std::int64_t StrictTable::integer(std::string_view key, std::int64_t fallback) {
  return has(key) ? integer(key) : (used_.emplace(key), fallback);
}

int StrictTable::int32(std::string_view key, int fallback) {
  const std::int64_t v = integer(key, fallback);
  if (v < std::numeric_limits<int>::min() || v > std::numeric_limits<int>::max())
    fail(key, "integer " + std::to_string(v) + " is out of range");
  return static_cast<int>(v);
}

std::string StrictTable::string(std::string_view key) {
  const toml::node* n = get(key, true);
  auto s = n->value_exact<std::string>();
  if (!s) fail(key, "expected a string, got " + type_name(*n));
  return *s;
}

std::string StrictTable::string(std::string_view key, std::string fallback) {
  return has(key) ? string(key) : (used_.emplace(key), std::move(fallback));
}

std::string StrictTable::choice(std::string_view key, const std::vector<std::string>& allowed, std::string fallback) {
  std::string v = string(key, std::move(fallback));
  for (const auto& a : allowed)
    if (a == v) return v;
  std::string list;
  for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
  fail(key, "'" + v + "' is not one of: " + list);
}

bool StrictTable::boolean(std::string_view key, bool fallback) {
  if (!has(key)) {
    used_.emplace(key);
    return fallback;
  }
  const toml::node* n = get(key, true);
  auto b = n->value_exact<bool>();
  if (!b) fail(key, "expected true or false, got " + type_name(*n));
  return *b;
}

std::vector<double> StrictTable::numbers(std::string_view key, std::optional<std::size_t> exact_size) {
  const toml::node* n = get(key, true);
  const toml::array* arr = n->as_array();
  if (!arr) fail(key, "expected an array of numbers, got " + type_name(*n));
  std::vector<double> out;
  for (const toml::node& e : *arr) {
    if (auto i = e.value_exact<std::int64_t>())
      out.push_back(static_cast<double>(*i));
    else if (auto f = e.value_exact<double>(); f && std::isfinite(*f))
      out.push_back(*f);
    else
      fail(key, "element " + std::to_string(out.size()) + " is not a finite number");
  }
  if (exact_size && out.size() != *exact_size)
    fail(key, "expected " + std::to_string(*exact_size) + " numbers, got " + std::to_string(out.size()));
  return out;
}

std::vector<std::string> StrictTable::strings(std::string_view key) {
  const toml::node* n = get(key, true);
  const toml::array* arr = n->as_array();
  if (!arr) fail(key, "expected an array of strings, got " + type_name(*n));
  std::vector<std::string> out;
  for (const toml::node& e : *arr) {
    auto s = e.value_exact<std::string>();
    if (!s) fail(key, "element " + std::to_string(out.size()) + " is not a string");
    out.push_back(*s);
  }
  return out;
}

std::vector<std::vector<double>> StrictTable::matrix(std::string_view key, std::size_t rows, std::size_t cols) {
  const toml::node* n = get(key, true);
  const toml::array* arr = n->as_array();
  const std::string shape = std::to_string(rows) + "x" + std::to_string(cols);
  if (!arr || arr->size() != rows)
    fail(key, "expected a " + shape + " matrix (array of " + std::to_string(rows) + " rows)");
  std::vector<std::vector<double>> out;
  for (const toml::node& row : *arr) {
    const toml::array* r = row.as_array();
    if (!r || r->size() != cols)
      fail(key, "row " + std::to_string(out.size()) + " is not " + std::to_string(cols) + " numbers");
    auto& dst = out.emplace_back();
    for (const toml::node& e : *r) {
      if (auto i = e.value_exact<std::int64_t>())
        dst.push_back(static_cast<double>(*i));
      else if (auto f = e.value_exact<double>(); f && std::isfinite(*f))
        dst.push_back(*f);
      else
        fail(key, "row " + std::to_string(out.size() - 1) + " holds a value that is not a finite number");
    }
  }
  return out;
}

StrictTable StrictTable::table(std::string_view key) {
  const toml::node* n = get(key, true);
  const toml::table* t = n->as_table();
  if (!t) fail(key, "expected a table, got " + type_name(*n));
  return StrictTable(*t, file_, join(section_, key));
}

std::optional<StrictTable> StrictTable::optional_table(std::string_view key) {
  if (!has(key)) {
    used_.emplace(key);
    return std::nullopt;
  }
  return table(key);
}

std::vector<StrictTable> StrictTable::tables(std::string_view key) {
  std::vector<StrictTable> out;
  const toml::node* n = get(key, false);
  if (!n) return out;
  const toml::array* arr = n->as_array();
  if (!arr || !arr->is_array_of_tables()) fail(key, "expected an array of tables ([[" + std::string(key) + "]])");
  for (const toml::node& e : *arr)
    out.emplace_back(*e.as_table(), file_, join(section_, key) + "[" + std::to_string(out.size()) + "]");
  return out;
}

std::vector<StrictTable> StrictTable::table_or_tables(std::string_view key) {
  const toml::node* n = get(key, true);
  if (n->is_table()) return {table(key)};
  return tables(key);
}

std::vector<std::string> StrictTable::keys() const {
  std::vector<std::pair<std::uint32_t, std::string>> found;
  for (const auto& [k, v] : *table_)
    if (!is_extension_name(k.str())) found.emplace_back(v.source().begin.line, std::string(k.str()));
  std::stable_sort(found.begin(), found.end());
  std::vector<std::string> out;
  for (auto& [line, k] : found) out.push_back(std::move(k));
  return out;
}

void StrictTable::finish() const {
  for (const auto& [k, v] : *table_) {
    if (used_.count(k.str()) == 0 && !is_extension_name(k.str())) {
      std::ostringstream os;
      os << file_ << ":" << v.source().begin.line << ": " << join(section_, k.str())
         << ": unknown key (check the spelling; every key is documented in the example file or "
         << "docs/run-files.md; keys of other tools begin with " << kExtensionPrefix << ")";
      throw dsp::InputError(os.str());
    }
  }
}

}  // namespace eical::drivers
