#pragma once
// Shared by the history tests: the suite's own PostgreSQL server (one per test process,
// started at the first use, stopped by the environment's TearDown, also when tests fail;
// it dies with the process if the process crashes), a fresh store location per test for
// each backend, and eical-result/1 documents that carry uncertainty_k2 and quality.verdict.
#include "tests/support/pg_scratch/scratch_server.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <unistd.h>
#include <cmath>
#include <filesystem>
#include <memory>
#include <random>
#include <string>

namespace eical::test {

namespace fs = std::filesystem;

inline std::unique_ptr<history::pg_scratch::ScratchServer>& pg_slot() {
  static std::unique_ptr<history::pg_scratch::ScratchServer> server;
  return server;
}

// The server, started on first use. A server that cannot start fails the test that needs
// it (with the reason): skipping is not passing.
inline history::pg_scratch::ScratchServer& pg() {
  auto& s = pg_slot();
  if (!s) s = std::make_unique<history::pg_scratch::ScratchServer>(history::pg_scratch::ServerOptions{.fsync = false});
  if (!s->running()) s->start();
  return *s;
}

class PgEnvironment : public ::testing::Environment {
 public:
  void TearDown() override { pg_slot().reset(); }
};

enum class Backend { sqlite, postgresql };

inline std::string backend_name(const ::testing::TestParamInfo<Backend>& info) {
  return info.param == Backend::sqlite ? "SQLite" : "PostgreSQL";
}

inline fs::path scratch(const std::string& tag) {
  const fs::path d =
      fs::temp_directory_path() / ("eical-history-" + tag + "-" + std::to_string(std::random_device{}()));
  fs::create_directories(d);
  return d;
}

// A new, empty store: a SQLite file in `dir`, or a new database on the suite's server.
inline std::string fresh_store(Backend b, const fs::path& dir) {
  static int n = 0;
  if (b == Backend::sqlite) return (dir / ("history-" + std::to_string(++n) + ".db")).string();
  return pg().create_database("t" + std::to_string(::getpid()) + "_" + std::to_string(++n));
}

struct CircleFigures {
  double backlash_x_um = 6.1, u_backlash_x_um = 0.4;
  double g_um = 6.3, u_g_um = 1.1;
  double mean_um = -2.1, u_mean_um = 0.8;
  bool uncertainty = true, verdict = true;
  std::string verdict_text = "ok";
  int trace_points = 2000;
};

// A circle result as results.md describes it (issue 16's uncertainty_k2 and verdict when
// asked for), with a trace long enough to be thinned for the store.
inline nlohmann::json circle_result(const std::string& run_id, const CircleFigures& f = {}) {
  nlohmann::json trace = {{"angle_deg", nlohmann::json::array()},
                          {"radius_deviation_um", nlohmann::json::array()},
                          {"direction", nlohmann::json::array()}};
  for (int i = 0; i < f.trace_points; ++i) {
    const double a = 720.0 * i / f.trace_points;
    trace["angle_deg"].push_back(std::fmod(a, 360.0));
    trace["radius_deviation_um"].push_back(f.mean_um + 0.5 * f.g_um * std::sin(2.0 * a * M_PI / 180.0));
    trace["direction"].push_back(i < f.trace_points / 2 ? "ccw" : "cw");
  }
  nlohmann::json j = {
      {"format", "eical-result/1"},
      {"run_id", run_id},
      {"program", "circle"},
      {"software", "eical 0.1.0"},
      {"quality", {{"degraded", false}, {"flags", nlohmann::json::array()}}},
      {"sensor_model", {{"identified", false}, {"source", "datasheet"}}},
      {"circle",
       {{"plane", "xy"},
        {"radius_nominal_mm", 10.0},
        {"feed_mm_min", 2500.0},
        {"direction", "both"},
        {"revolutions", 2},
        {"arc_deg", 360.0},
        {"radius_mean_deviation_um", f.mean_um},
        {"circular_deviation_G_um", f.g_um},
        {"circular_hysteresis_H_um", nullptr},
        {"radial_deviation_F_max_um", 3.4},
        {"radial_deviation_F_min_um", -2.9},
        {"trace", trace}}},
      {"diagnostics",
       {{"backlash_x_um", f.backlash_x_um},
        {"backlash_y_um", 0.3},
        {"squareness_urad", 12.5},
        {"servo_mismatch_ms", nullptr},
        {"notes", nlohmann::json::array()}}},
      {"pipeline", {{"rest_window_samples", 1000}, {"supports", {{"standstills", 4}}}}},
  };
  j["quality"]["flags"].push_back("circle.circular_hysteresis_H_um: null, ISO 230-4 H needs both directions");
  if (f.verdict) j["quality"]["verdict"] = f.verdict_text;
  if (f.uncertainty)
    j["uncertainty_k2"] = {{"circle.radius_mean_deviation_um", f.u_mean_um},
                           {"circle.circular_deviation_G_um", f.u_g_um},
                           {"diagnostics.backlash_x_um", f.u_backlash_x_um},
                           {"diagnostics.backlash_y_um", 0.4},
                           {"diagnostics.squareness_urad", 3.0}};
  return j;
}

}  // namespace eical::test
