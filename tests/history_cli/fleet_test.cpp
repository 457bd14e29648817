// A shop's fleet: three eicald on one DDS domain (loopback), each measuring its simulated
// circle again and again, and one `eical collect` storing what it hears in a real
// PostgreSQL database. The collector is stopped while the machines go on measuring and
// started again: it gets the results it missed (Result is transient-local and keyed by
// machine + run id), and those it had are not stored twice. Every stored result is the
// result.json its eicald wrote, figure for figure.
#include "cli_support.hpp"
#include "drivers/dds/domain_claim.hpp"
#include "history/record/result_record.hpp"
#include "history/store/store.hpp"

#include <csignal>
#include <map>
#include <set>
#include <thread>

namespace eical::test {
namespace {

using namespace std::chrono_literals;
using Key = std::pair<std::string, std::string>;  // machine, run id

const std::vector<std::string> kMachines = {"fleet-maho", "fleet-hermle", "fleet-dmg"};

fs::path daemon_config(const fs::path& dir, const std::string& machine, int domain, int seed) {
  const fs::path file = dir / (machine + ".toml");
  std::ofstream os(file);
  os << "[source]\nkind = \"sim\"\npacing = \"realtime\"\n"
     << "[source.sim]\nprogram = \"circle\"\nradius_mm = 5.0\nfeed_mm_min = 3000.0\nrepeats = 1\nseed = " << seed
     << "\nidle_s = 0.5\nrepeat_program = true\n"
     << "[triggers]\ninputs = [\"frame\"]\n"
     << "[dds]\ndomain_id = " << domain
     << "\nconfig_uri = \"file://" EICAL_SOURCE_DIR "/config/cyclonedds-loopback.xml\"\nlive_rate_hz = 10.0\n"
     << "[recording]\ndir = \"" << (dir / machine).string() << "\"\ngzip = false\n"
     << "[limits]\nmax_measurement_s = 60.0\n"
     << "[realtime]\nsched_fifo_priority = 0\nmlockall = false\n"
     << "[machine]\nname = \"" << machine << "\"\n";
  return file;
}

// What the daemons have written: (machine, run id) → run directory, result.json complete.
std::map<Key, fs::path> written(const fs::path& dir) {
  std::map<Key, fs::path> out;
  for (const auto& m : kMachines) {
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(dir / m, ec))
      if (e.is_directory() && e.path().filename().string()[0] != '.' && fs::exists(e.path() / "result.json"))
        out[{m, e.path().filename().string()}] = e.path();
  }
  return out;
}

std::set<Key> stored(const std::string& db) {
  std::set<Key> out;
  try {
    for (const auto& s : history::Store::open(db)->list({})) out.insert({s.machine, s.run_id});
  } catch (const std::exception&) {
    // not created yet
  }
  return out;
}

template <class P>
bool wait_until(P pred, std::chrono::seconds timeout) {
  for (auto end = std::chrono::steady_clock::now() + timeout; std::chrono::steady_clock::now() < end;
       std::this_thread::sleep_for(250ms))
    if (pred()) return true;
  return pred();
}

std::size_t count_of(const std::set<Key>& s, const std::string& machine) {
  return static_cast<std::size_t>(std::count_if(s.begin(), s.end(), [&](const Key& k) { return k.first == machine; }));
}

TEST(Fleet, ThreeEicaldOneCollectorIntoPostgresqlWithoutLossOrDuplicates) {
  const fs::path dir = scratch("fleet");
  const std::string db = pg().create_database("fleet_" + std::to_string(::getpid()));
  ::setenv("CYCLONEDDS_URI", "file://" EICAL_SOURCE_DIR "/config/cyclonedds-loopback.xml", 1);
  const int domain = drivers::dds::claim_free_domain();
  const std::vector<std::string> collect = {
      EICAL_CLI,   "collect", "--db", db, "--domain", std::to_string(domain), "--spool", (dir / "spool").string(),
      "--retry-s", "0.5"};
  auto collector = std::make_unique<ChildProcess>(collect, (dir / "collect-1.log").string());
  std::vector<std::unique_ptr<ChildProcess>> daemons;
  for (std::size_t i = 0; i < kMachines.size(); ++i)
    daemons.push_back(std::make_unique<ChildProcess>(
        std::vector<std::string>{EICALD_BIN, "--config",
                                 daemon_config(dir, kMachines[i], domain, static_cast<int>(i + 1)).string()},
        (dir / (kMachines[i] + ".log")).string()));
  auto logs = [&] {
    std::string s = "\ncollect-1:\n" + slurp(dir / "collect-1.log") + "\ncollect-2:\n" + slurp(dir / "collect-2.log");
    for (const auto& m : kMachines) s += "\n" + m + ":\n" + slurp(dir / (m + ".log"));
    return s;
  };

  // Every machine's first result reaches the store.
  ASSERT_TRUE(wait_until(
      [&] {
        const auto s = stored(db);
        return std::all_of(kMachines.begin(), kMachines.end(), [&](const auto& m) { return count_of(s, m) >= 1; });
      },
      120s))
      << logs();

  // The collector goes away; the machines go on measuring.
  collector->signal(SIGTERM);
  ASSERT_EQ(collector->wait_exit(30s), std::optional<int>(0)) << logs();
  collector.reset();
  const auto had = stored(db);
  ASSERT_TRUE(wait_until(
      [&] {
        const auto w = written(dir);
        return std::all_of(kMachines.begin(), kMachines.end(), [&](const auto& m) {
          return std::count_if(w.begin(), w.end(), [&](const auto& kv) { return kv.first.first == m; }) >
                 static_cast<std::ptrdiff_t>(count_of(had, m));
        });
      },
      120s))
      << logs();

  // Back again: what was missed comes in, nothing twice.
  collector = std::make_unique<ChildProcess>(collect, (dir / "collect-2.log").string());
  const auto snapshot = written(dir);
  ASSERT_TRUE(wait_until(
      [&] {
        const auto s = stored(db);
        return std::all_of(snapshot.begin(), snapshot.end(), [&](const auto& kv) { return s.count(kv.first) > 0; });
      },
      120s))
      << logs();
  for (auto& d : daemons) d->signal(SIGTERM);
  for (auto& d : daemons) EXPECT_EQ(d->wait_exit(60s), std::optional<int>(0)) << logs();
  collector->signal(SIGTERM);
  ASSERT_EQ(collector->wait_exit(30s), std::optional<int>(0)) << logs();
  const std::string second = slurp(dir / "collect-2.log");
  // The restarted collector heard the results the first had stored again, and kept one each.
  const auto summary = second.find("collect: ");
  ASSERT_NE(summary, std::string::npos) << second;
  unsigned received = 0, added = 0, again = 0;
  ASSERT_EQ(std::sscanf(second.c_str() + summary, "collect: %u results received, %u stored, %u already stored",
                        &received, &added, &again),
            3)
      << second;
  EXPECT_GE(again, had.size()) << second;
  EXPECT_GE(added, 1u) << second;

  // Each stored result is a result.json of its machine, figure for figure; one row per key.
  auto store = history::Store::open(db);
  const auto rows = store->list({});
  const auto all = written(dir);
  std::set<Key> keys;
  for (const auto& row : rows) {
    EXPECT_TRUE(keys.insert({row.machine, row.run_id}).second) << "twice: " << row.machine << " " << row.run_id;
    const auto it = all.find({row.machine, row.run_id});
    ASSERT_NE(it, all.end()) << row.machine << " " << row.run_id << " is not a result its eicald wrote";
    const auto rec = store->find(row.run_id, row.machine).at(0);
    EXPECT_EQ(rec.run_path, it->second.string());
    std::ifstream is(it->second / "result.json");
    const auto want = history::figures_of(nlohmann::json::parse(is));
    ASSERT_EQ(rec.figures.size(), want.size());
    for (std::size_t i = 0; i < want.size(); ++i) {
      EXPECT_EQ(rec.figures[i].name, want[i].name);
      EXPECT_EQ(rec.figures[i].value, want[i].value) << row.run_id << " " << want[i].name;
    }
  }
  for (const auto& m : kMachines) EXPECT_GE(count_of(keys, m), 2u) << m;
  std::printf(
      "fleet: %zu results of %zu machines stored; the restarted collector received %u, stored %u, %u already stored\n",
      rows.size(), kMachines.size(), received, added, again);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace eical::test
