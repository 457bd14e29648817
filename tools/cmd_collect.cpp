// eical collect: a shop's fleet into one history. Subscribes to Result on the DDS domain and
// stores the results of every eicald it hears (Result is keyed by machine + run id and
// transient-local: a collector started late or restarted gets each daemon's results again,
// and the store's key turns those it has into no-ops, never duplicates). Results pass the
// same spool as eicald's, so a database that goes away loses nothing.
#include "tools/commands.hpp"

#if EICAL_HAVE_DDS
#include "daemon/system/notify.hpp"
#include "drivers/dds/bus.hpp"
#include "history/record/result_record.hpp"
#include "history/spool/sink.hpp"
#include "history/sql/pg_connection.hpp"

#include <nlohmann/json.hpp>

#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <memory>

namespace eical::tools {
namespace {

std::atomic<bool> g_stop{false};
extern "C" void on_signal(int) { g_stop = true; }

}  // namespace

void register_collect(CLI::App& app) {
  struct Opt {
    std::string db, spool = "/var/lib/eical/collect-spool", uri;
    int domain = 0, results = 0;
    double retry_s = 30.0, timeout_s = 0.0;
  };
  auto o = std::make_shared<Opt>();
  auto* cmd =
      app.add_subcommand("collect", "Store the results of every eicald on the DDS domain in one history (a fleet)");
  cmd->add_option("--db", o->db, "history store: postgresql://user@host/db (or a SQLite file)")
      ->envname("EICAL_HISTORY_DB")
      ->required();
  cmd->add_option("--domain", o->domain, "DDS domain id")->default_val(0);
  cmd->add_option("--dds-config", o->uri, "Cyclone DDS XML (file://...); default $CYCLONEDDS_URI");
  cmd->add_option("--spool", o->spool, "where results wait while the store is unavailable")->default_val(o->spool);
  cmd->add_option("--retry-s", o->retry_s, "an unavailable store is tried again after this many seconds")
      ->default_val(30.0)
      ->check(CLI::Range(0.1, 3600.0));
  cmd->add_option("--results", o->results, "exit after this many results received (0 = run until SIGINT/SIGTERM)")
      ->default_val(0);
  cmd->add_option("--timeout", o->timeout_s, "exit after this many seconds (0 = never)")->default_val(0.0);
  cmd->callback([o] {
    if (!o->uri.empty()) ::setenv("CYCLONEDDS_URI", o->uri.c_str(), 1);
    struct sigaction sa {};
    sa.sa_handler = on_signal;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, nullptr);
    sigaction(SIGTERM, &sa, nullptr);
    history::Sink sink({o->db, o->spool, o->retry_s, true}, [](history::Sink::Level l, const std::string& m) {
      std::fprintf(l == history::Sink::Level::error ? stderr : stdout, "%s\n", m.c_str());
      std::fflush(l == history::Sink::Level::error ? stderr : stdout);
    });
    drivers::dds::Bus bus(o->domain, drivers::dds::Role::hmi);
    std::printf("collecting results on DDS domain %d into %s\n", o->domain, history::sql::redact_uri(o->db).c_str());
    std::fflush(stdout);
    // Type=notify (systemd/eical-collect.service): ready once the bus and the spool are up;
    // the watchdog is fed from this loop, so a collector whose loop hangs is restarted.
    const daemon::SystemdNotifier notifier;
    notifier.ready("collecting on DDS domain " + std::to_string(o->domain));
    auto fed = std::chrono::steady_clock::now();
    const auto end =
        std::chrono::steady_clock::now() + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                               std::chrono::duration<double>(o->timeout_s > 0 ? o->timeout_s : 1e9));
    int received = 0;
    while (!g_stop && std::chrono::steady_clock::now() < end && (o->results == 0 || received < o->results)) {
      if (const auto every = notifier.watchdog_interval(); every && std::chrono::steady_clock::now() - fed >= *every) {
        notifier.watchdog();
        fed = std::chrono::steady_clock::now();
      }
      const auto m = bus.take_result(std::chrono::milliseconds(300));
      if (!m) continue;
      ++received;
      try {
        const auto doc = nlohmann::json::parse(m->json);
        history::Provenance p{
            m->machine, m->measured_at, m->run_path,
            m->software_version.empty() ? std::nullopt : std::optional<std::string>(m->software_version),
            m->sensor_calibration};
        sink.submit(history::record_from_result(doc, p));
        std::printf("received %s %s (%s)\n", m->machine.c_str(), m->program_id.c_str(), m->program.c_str());
      } catch (const std::exception& e) {
        std::fprintf(stderr, "eical collect: result %s of %s not stored: %s\n", m->program_id.c_str(),
                     m->machine.c_str(), e.what());
      }
      std::fflush(stdout);
    }
    // What arrived goes in before the exit (or stays spooled for the next start).
    notifier.stopping();
    (void)sink.wait_drained(std::chrono::seconds(10));
    const auto c = sink.counts();
    std::printf("collect: %d results received, %llu stored, %llu already stored, %zu waiting in %s\n", received,
                static_cast<unsigned long long>(c.stored), static_cast<unsigned long long>(c.duplicates),
                sink.waiting(), o->spool.c_str());
  });
}

}  // namespace eical::tools
#else
namespace eical::tools {
void register_collect(CLI::App& app) {
  auto* cmd =
      app.add_subcommand("collect", "Store the results of every eicald on the DDS domain (this build has no DDS)");
  cmd->callback(
      [] { throw std::runtime_error("eical was built without Cyclone DDS (EICAL_BUILD_DAEMON=OFF): no collect"); });
}
}  // namespace eical::tools
#endif
