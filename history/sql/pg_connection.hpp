#pragma once
// The PostgreSQL backend (libpq): a shop's fleet database, `postgresql://user@host/db` or
// any libpq connection URI. Statements are prepared once per connection and executed with
// text parameters (the server infers their types from the schema).
#include "history/sql/connection.hpp"

#include <memory>
#include <string>

namespace eical::history::sql {

// True for a location libpq should open ("postgresql://..." or "postgres://...").
bool is_postgresql_uri(const std::string& location);

// The URI with any password replaced by "***" (for messages and logs).
std::string redact_uri(const std::string& uri);

// Connects (libpq's connect_timeout defaults to 5 s unless the URI sets it). Throws
// SqlError naming the redacted URI and libpq's reason (server down, no such database, ...).
std::unique_ptr<Connection> open_postgresql(const std::string& uri);

}  // namespace eical::history::sql
