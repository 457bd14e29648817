// Registers the suite's PostgreSQL environment (TearDown stops the server).
#include "history_support.hpp"

namespace {
[[maybe_unused]] const auto* const kPgEnvironment = ::testing::AddGlobalTestEnvironment(new eical::test::PgEnvironment);
}
