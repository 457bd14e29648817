// Schema versions on both backends: a new store is created at the current version; a store
// an earlier eical left is upgraded in place with its results intact; a store of a newer
// schema is refused with a clear message and left untouched; SQLite files that are not a
// store (missing, corrupt) are named with the cause.
#include "history/store/schema.hpp"
#include "history/record/result_record.hpp"
#include "history/sql/pg_connection.hpp"
#include "history/sql/sqlite_connection.hpp"
#include "history/store/store.hpp"
#include "history_support.hpp"

#include <fstream>

namespace eical::test {
namespace {

using history::Store;

std::unique_ptr<history::sql::Connection> connect(Backend b, const std::string& location) {
  if (b == Backend::sqlite) return history::sql::open_sqlite(location, {.create = true});
  return history::sql::open_postgresql(location);
}

history::Record sample(const std::string& run) {
  return history::record_from_result(circle_result(run),
                                     {"maho-1", "2026-11-12T09:11:00Z", "/runs/" + run, std::nullopt, ""});
}

class SchemaTest : public ::testing::TestWithParam<Backend> {
 protected:
  void SetUp() override { dir_ = scratch("schema"), location_ = fresh_store(GetParam(), dir_); }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
  std::string location_;
};

TEST_P(SchemaTest, NewStoreIsAtTheCurrentVersion) {
  auto s = Store::open(location_, {.create = true});
  EXPECT_EQ(s->schema_version(), history::kSchemaVersion);
}

TEST_P(SchemaTest, AStoreOfAnEarlierVersionIsUpgradedWithItsResults) {
  {
    Store v1(connect(GetParam(), location_), {.create = true}, 1);  // as the first eical left it
    ASSERT_EQ(v1.schema_version(), 1);
    ASSERT_EQ(v1.add(sample("before-upgrade")), history::AddOutcome::added);
  }
  auto s = Store::open(location_);
  EXPECT_EQ(s->schema_version(), history::kSchemaVersion);
  const auto r = s->find("before-upgrade");
  ASSERT_EQ(r.size(), 1u);
  EXPECT_EQ(r[0].figure("diagnostics.backlash_x_um")->value.value(), 6.1);
  EXPECT_EQ(s->trend("diagnostics.backlash_x_um", {.machine = "maho-1"}).size(), 1u);
}

TEST_P(SchemaTest, AStoreOfANewerSchemaIsRefusedAndLeftUntouched) {
  {
    auto s = Store::open(location_, {.create = true});
    s->add(sample("kept"));
    s->connection().exec("UPDATE eical_schema SET version = 99");
  }
  try {
    (void)Store::open(location_, {.create = true});
    FAIL() << "opened a store of schema 99";
  } catch (const history::SchemaError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("schema version 99"), std::string::npos) << m;
    EXPECT_NE(m.find("up to " + std::to_string(history::kSchemaVersion)), std::string::npos) << m;
    EXPECT_NE(m.find("untouched"), std::string::npos) << m;
  }
  auto c = connect(GetParam(), location_);
  EXPECT_EQ(history::schema_version(*c), 99);
  EXPECT_EQ(history::sql::to_int(c->query("SELECT count(*) FROM results").at(0).at(0)), 1);
}

TEST_P(SchemaTest, ADatabaseWithoutTheSchemaIsNotOpenedForReading) {
  if (GetParam() == Backend::sqlite) {
    history::sql::open_sqlite(location_, {.create = true});  // an empty SQLite file
  }
  try {
    (void)Store::open(location_);
    FAIL() << "opened a database that is no store";
  } catch (const history::SchemaError& e) {
    EXPECT_NE(std::string(e.what()).find("not an eical history store"), std::string::npos) << e.what();
  }
}

INSTANTIATE_TEST_SUITE_P(Backends, SchemaTest, ::testing::Values(Backend::sqlite, Backend::postgresql), backend_name);

TEST(SchemaSqlite, MissingAndCorruptFilesNameTheCause) {
  const fs::path dir = scratch("files");
  try {
    (void)Store::open((dir / "none.db").string());
    FAIL();
  } catch (const history::sql::SqlError& e) {
    EXPECT_NE(std::string(e.what()).find("no history store there"), std::string::npos) << e.what();
  }
  try {
    (void)Store::open((dir / "no-such-dir" / "h.db").string(), {.create = true});
    FAIL();
  } catch (const history::sql::SqlError& e) {
    EXPECT_NE(std::string(e.what()).find("does not exist"), std::string::npos) << e.what();
  }
  {
    std::ofstream os(dir / "corrupt.db", std::ios::binary);
    for (int i = 0; i < 4096; ++i) os.put(static_cast<char>(i * 7 + 3));
  }
  try {
    (void)Store::open((dir / "corrupt.db").string(), {.create = true});
    FAIL();
  } catch (const history::sql::SqlError& e) {
    EXPECT_NE(std::string(e.what()).find("not a database"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("corrupt.db"), std::string::npos) << e.what();
  }
  fs::remove_all(dir);
}

TEST(SchemaPostgresql, AnUnreachableServerNamesTheCauseWithoutThePassword) {
  try {
    (void)Store::open("postgresql://eical:secret@/history?host=/nonexistent&connect_timeout=2");
    FAIL();
  } catch (const history::sql::SqlError& e) {
    const std::string m = e.what();
    EXPECT_EQ(m.find("secret"), std::string::npos) << m;
    EXPECT_NE(m.find("eical:***@"), std::string::npos) << m;
    EXPECT_NE(m.find("/nonexistent"), std::string::npos) << m;
  }
}

}  // namespace
}  // namespace eical::test
