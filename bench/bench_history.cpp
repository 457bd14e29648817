// Calibration history benchmark (issue 18): 100,000 results inserted into each store (a
// SQLite file; a PostgreSQL server of the benchmark's own with fsync on, on a Unix socket),
// then the queries a user runs over them. Printed per store:
//   * insert, batched: add_many in transactions of --batch results (a backlog draining, a
//     `history add` of many runs) — results per second;
//   * insert, one commit per result (eicald and the collector in steady state) for the
//     first --single results — milliseconds per result;
//   * trend of one figure of one machine over all its results, the same over the fleet,
//     and the newest 20 results of a machine: median of 9 runs, each on a new connection
//     as `eical history` makes one (PostgreSQL analysed first, as autovacuum would).
// Each result: a circle with 27 figures, each with its uncertainty, and a stored document of
// the size eical stores (720-point trace), drawn from 50 distinct documents.
//   bench_history [--results 100000] [--machines 30] [--batch 1000] [--single 1000] [--store sqlite|postgresql|both]
#include "history/store/store.hpp"
#include "tests/support/pg_scratch/scratch_server.hpp"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <sys/stat.h>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <random>

namespace {

namespace fs = std::filesystem;
using eical::history::Record;
using Clock = std::chrono::steady_clock;

const char* const kFigures[] = {"circle.circular_deviation_G_um",
                                "circle.radial_deviation_F_max_um",
                                "circle.radial_deviation_F_min_um",
                                "circle.radius_mean_deviation_um",
                                "circle.circular_hysteresis_H_um",
                                "diagnostics.backlash_x_um",
                                "diagnostics.backlash_y_um",
                                "diagnostics.cyclic_error_x_um",
                                "diagnostics.cyclic_error_y_um",
                                "diagnostics.cyclic_pitch_mm",
                                "diagnostics.lateral_play_x_um",
                                "diagnostics.lateral_play_y_um",
                                "diagnostics.model_residual_rms_um",
                                "diagnostics.reversal_spike_x_um",
                                "diagnostics.reversal_spike_y_um",
                                "diagnostics.scale_mismatch_ppm",
                                "diagnostics.servo_lag_x_ms",
                                "diagnostics.servo_lag_y_ms",
                                "diagnostics.servo_mismatch_ms",
                                "diagnostics.squareness_urad",
                                "diagnostics.stick_slip_um",
                                "diagnostics.straightness_x_um",
                                "diagnostics.straightness_y_um",
                                "diagnostics.vibration_um",
                                "reference_comparison.radius_deviation_error_rms_um",
                                "reference_comparison.reference_circular_deviation_G_um",
                                "reference_comparison.reference_radius_mean_deviation_um"};

// A circle result document as the store keeps it (trace thinned to 720 points).
std::string document(std::mt19937& rng, int k) {
  std::normal_distribution<double> n(0.0, 0.3);
  nlohmann::json t = {{"angle_deg", nlohmann::json::array()},
                      {"radius_deviation_um", nlohmann::json::array()},
                      {"direction", nlohmann::json::array()},
                      {"stored_every", 5}};
  for (int i = 0; i < 720; ++i) {
    const double a = std::fmod(i * 1.0, 360.0);
    t["angle_deg"].push_back(std::round(a * 1000) / 1000);
    t["radius_deviation_um"].push_back(std::round((2.0 * std::sin(2 * a * M_PI / 180) + n(rng)) * 1000) / 1000);
    t["direction"].push_back(i < 360 ? "ccw" : "cw");
  }
  nlohmann::json d = {
      {"format", "eical-result/1"},
      {"run_id", "template-" + std::to_string(k)},
      {"program", "circle"},
      {"quality", {{"degraded", false}, {"verdict", "ok"}, {"flags", nlohmann::json::array()}}},
      {"circle", {{"plane", "xy"}, {"radius_nominal_mm", 10.0}, {"feed_mm_min", 2500.0}, {"trace", t}}}};
  nlohmann::json u = nlohmann::json::object();
  for (const char* f : kFigures) u[f] = 0.4;
  d["uncertainty_k2"] = u;
  return d.dump();
}

struct Timing {
  double batched_s = 0, single_ms = 0, trend_machine_ms = 0, trend_fleet_ms = 0, latest_ms = 0;
  std::size_t trend_machine_points = 0, trend_fleet_points = 0;
  double bytes = 0;
};

// `f` returns the milliseconds of what it measures; the median of `runs`.
double median_ms(const std::function<double()>& f, int runs = 9) {
  std::vector<double> ms;
  for (int i = 0; i < runs; ++i) ms.push_back(f());
  std::sort(ms.begin(), ms.end());
  return ms[ms.size() / 2];
}

Timing run(const std::string& location, std::size_t results, int machines, std::size_t batch, std::size_t single) {
  auto store = eical::history::Store::open(location, {.create = true});
  std::mt19937 rng(18);
  std::vector<std::string> docs;
  for (int k = 0; k < 50; ++k) docs.push_back(document(rng, k));
  std::normal_distribution<double> val(0.0, 3.0);
  // Result i: machine i % machines, one hour apart per machine.
  auto make = [&](std::size_t i) {
    Record r;
    r.machine = "machine-" + std::to_string(i % static_cast<std::size_t>(machines));
    r.run_id = "run-" + std::to_string(i);
    r.program = "circle";
    const std::time_t t =
        1767225600 + static_cast<std::time_t>(i / static_cast<std::size_t>(machines)) * 3600;  // from 2026-01-01
    std::tm tm{};
    gmtime_r(&t, &tm);
    char b[32];
    std::strftime(b, sizeof b, "%Y-%m-%dT%H:%M:%SZ", &tm);
    r.measured_at = b;
    r.verdict = "ok";
    r.run_path = "/var/lib/eical/runs/" + r.run_id;
    r.software_version = "eical 0.1.0";
    r.sensor_calibration = "datasheet";
    for (const char* f : kFigures) r.figures.push_back({f, val(rng), 0.4});
    std::sort(r.figures.begin(), r.figures.end(), [](const auto& a, const auto& b2) { return a.name < b2.name; });
    r.document = docs[i % docs.size()];
    return r;
  };
  Timing t;
  for (std::size_t i = 0; i < std::min(results, 1000ul); ++i) t.bytes += static_cast<double>(make(i).document.size());
  t.bytes /= static_cast<double>(std::min(results, 1000ul));
  // One commit per result first (a store that is still small), then the rest batched.
  const std::size_t n_single = std::min(single, results);
  auto t0 = Clock::now();
  for (std::size_t i = 0; i < n_single; ++i) store->add(make(i));
  t.single_ms =
      n_single ? std::chrono::duration<double, std::milli>(Clock::now() - t0).count() / static_cast<double>(n_single)
               : 0;
  double inserting_s = 0;
  for (std::size_t first = n_single; first < results; first += batch) {
    std::vector<Record> rs;
    for (std::size_t i = first; i < std::min(results, first + batch); ++i) rs.push_back(make(i));
    t0 = Clock::now();
    store->add_many(rs);
    inserting_s += std::chrono::duration<double>(Clock::now() - t0).count();
    if ((first / batch) % 10 == 0)
      std::fprintf(stderr, "\r  %zu of %zu inserted ", first + rs.size(), results), std::fflush(stderr);
  }
  std::fprintf(stderr, "\r%40s\r", "");
  t.batched_s = inserting_s;
  // PostgreSQL's autovacuum analyses a table soon after a bulk load; done here at once so
  // that the planner sees what a running server would (SQLite's plans need no statistics).
  if (store->connection().dialect() == eical::history::sql::Dialect::postgresql) store->connection().exec("ANALYZE");
  store.reset();
  // Each query on a connection of its own, as `eical history` opens one per command (no
  // statement or page cache of the connection carried over; the OS's file cache is warm).
  const std::string figure = "diagnostics.backlash_x_um";
  auto fresh = [&](auto&& query) {
    return median_ms([&] {
      auto s = eical::history::Store::open(location);
      const auto start = Clock::now();
      query(*s);
      return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
    });
  };
  t.trend_machine_ms = fresh(
      [&](eical::history::Store& s) { t.trend_machine_points = s.trend(figure, {.machine = "machine-7"}).size(); });
  t.trend_fleet_ms = fresh([&](eical::history::Store& s) { t.trend_fleet_points = s.trend(figure, {}).size(); });
  t.latest_ms = fresh([&](eical::history::Store& s) { (void)s.list({.machine = "machine-7", .limit = 20}); });
  return t;
}

void print(const char* name, const Timing& t, std::size_t results, std::size_t batched, std::size_t single,
           const std::string& size) {
  std::printf("%s:\n", name);
  std::printf("  insert, one commit per result (first %zu):   %8.2f ms per result\n", single, t.single_ms);
  std::printf("  insert, %zu results in batches:           %8.1f s  = %.0f results/s\n", batched, t.batched_s,
              static_cast<double>(batched) / t.batched_s);
  std::printf("  trend of one figure, one machine (%zu pts): %8.2f ms\n", t.trend_machine_points, t.trend_machine_ms);
  std::printf("  trend of one figure, fleet (%zu pts):     %8.1f ms\n", t.trend_fleet_points, t.trend_fleet_ms);
  std::printf("  newest 20 results of a machine:            %8.2f ms\n", t.latest_ms);
  std::printf("  store size: %s for %zu results (document %.1f kB each)\n", size.c_str(), results, t.bytes / 1000.0);
  std::fflush(stdout);
}

std::string megabytes(double bytes) {
  char b[32];
  std::snprintf(b, sizeof b, "%.0f MB", bytes / 1e6);
  return b;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app("eical calibration history benchmark");
  std::size_t results = 100000, batch = 1000, single = 1000;
  int machines = 30;
  std::string which = "both";
  app.add_option("--results", results, "results to insert")->check(CLI::PositiveNumber);
  app.add_option("--machines", machines, "machines they come from")->check(CLI::PositiveNumber);
  app.add_option("--batch", batch, "results per transaction when batched")->check(CLI::PositiveNumber);
  app.add_option("--single", single, "results first inserted one commit each");
  app.add_option("--store", which, "sqlite, postgresql or both")
      ->check(CLI::IsMember({"sqlite", "postgresql", "both"}));
  CLI11_PARSE(app, argc, argv);
  std::printf("%zu circle results of %d machines, 27 figures each with its uncertainty\n", results, machines);
  const std::size_t batched = results - std::min(single, results);
  if (which != "postgresql") {
    const fs::path dir = fs::temp_directory_path() / ("eical-bench-history-" + std::to_string(::getpid()));
    fs::create_directories(dir);
    const fs::path db = dir / "history.db";
    const Timing t = run(db.string(), results, machines, batch, single);
    double bytes = 0;
    for (const auto& e : fs::directory_iterator(dir)) bytes += static_cast<double>(e.file_size());
    print("SQLite (WAL, synchronous=FULL)", t, results, batched, single, megabytes(bytes));
    fs::remove_all(dir);
  }
  if (which != "sqlite") {
    eical::history::pg_scratch::ScratchServer server;  // fsync on: as a real server commits
    const std::string uri = server.create_database("bench");
    const Timing t = run(uri, results, machines, batch, single);
    auto store = eical::history::Store::open(uri);
    const auto rows = store->connection().query("SELECT pg_database_size(current_database())");
    print("PostgreSQL 15 (local, Unix socket, fsync on)", t, results, batched, single,
          megabytes(std::stod(rows.at(0).at(0).value_or("0"))));
  }
  return 0;
}
