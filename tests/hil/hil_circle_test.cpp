// Hardware in the loop: the real eicald (sim backend running the circle program written by
// `eical gen-nc circle`, loopback DDS, triggers accepted only from DDS) and this test as
// the NC and the HMI. The test sends M101/M102/M103 over the Command topic at the NC
// program's times, receives Result and Trace, and checks that the Result equals
// `eical analyze --json` on the run eicald recorded.
#include "child_process.hpp"
#include "hil_support.hpp"
#include "sim/nc/trajectory.hpp"

#include <nlohmann/json.hpp>

#include <cmath>

namespace eical::test {
namespace {

constexpr double kFs = 10000.0;

// Every number equal to printing precision (relative 1e-9), every string and key equal.
void expect_same(const nlohmann::json& a, const nlohmann::json& b, const std::string& path, int& differences) {
  if (a.is_number() && b.is_number()) {
    const double x = a.get<double>(), y = b.get<double>();
    if (!(std::abs(x - y) <= 1e-9 * std::max(1.0, std::abs(x)))) {
      ADD_FAILURE() << path << ": " << x << " (DDS) vs " << y << " (analyze)";
      ++differences;
    }
    return;
  }
  if (a.type() != b.type()) {
    ADD_FAILURE() << path << ": " << a.dump() << " vs " << b.dump();
    ++differences;
    return;
  }
  if (a.is_object()) {
    for (auto it = a.begin(); it != a.end(); ++it) {
      if (!b.contains(it.key())) {
        ADD_FAILURE() << path << "/" << it.key() << " missing in analyze";
        ++differences;
      } else {
        expect_same(it.value(), b[it.key()], path + "/" + it.key(), differences);
      }
    }
    for (auto it = b.begin(); it != b.end(); ++it)
      if (!a.contains(it.key()))
        ADD_FAILURE() << path << "/" << it.key() << " missing in the DDS Result", ++differences;
  } else if (a.is_array()) {
    if (a.size() != b.size()) {
      ADD_FAILURE() << path << ": " << a.size() << " vs " << b.size() << " elements";
      ++differences;
      return;
    }
    for (std::size_t i = 0; i < a.size(); ++i) expect_same(a[i], b[i], path + "/" + std::to_string(i), differences);
  } else if (a != b) {
    ADD_FAILURE() << path << ": " << a.dump() << " vs " << b.dump();
    ++differences;
  }
}

TEST(Hil, DdsTriggeredCircleResultEqualsAnalyzeOfTheRecording) {
  const fs::path dir = scratch_dir("circle");
  int rc = -1;
  ASSERT_TRUE(run_capture({EICAL_CLI, "gen-nc", "circle", "--radius", "10", "--feed", "2500", "--repeats", "2", "-o",
                           (dir / "circle.ngc").string(), "--meta", (dir / "circle.toml").string()},
                          30s, &rc));
  ASSERT_EQ(rc, 0) << "eical gen-nc failed";
  HilConfig hc;
  hc.domain = hil_domain(1);
  hc.program_file = dir / "circle.toml";
  hc.recording_dir = dir / "runs";
  const fs::path cfg = write_config(dir, hc);
  ChildProcess eicald({EICALD_BIN, "--config", cfg.string()}, (dir / "eicald.log").string());
  ASSERT_TRUE(eicald.started());

  NcOnBus nc(hc.domain);
  ASSERT_TRUE(nc.handshake(30s)) << "eicald did not answer on DDS; log:\n" << slurp(dir / "eicald.log");
  const auto st = nc.status(15s, [](const drivers::dds::StatusMsg& s) { return s.sample_time_ns > 0; });
  ASSERT_TRUE(st) << "no Status with the sample clock; log:\n" << slurp(dir / "eicald.log");

  // The NC program's M-code times, and where the sim's program cycle puts them on the DAQ
  // clock (the sim runs the program, then rests idle_s, and again).
  const auto tr = sim::nc::interpolate_gcode(slurp(dir / "circle.ngc"), "circle.ngc", {});
  const auto n_prog = static_cast<std::int64_t>(std::ceil(tr.duration_s() * kFs)) + 1;
  const std::int64_t period = n_prog + std::llround(hc.idle_s * kFs);
  const double t0_ns = static_cast<double>(st->sample_time_ns) - static_cast<double>(st->sample_index) * 1e9 / kFs;
  std::vector<sim::nc::TimedTrigger> codes;
  for (const auto& t : tr.triggers())
    if (t.code >= 101 && t.code <= 103) codes.push_back(t);
  ASSERT_GE(codes.size(), 4u);
  ASSERT_EQ(codes.front().code, 101);
  auto due_ns = [&](std::int64_t cycle, double t_s) {
    return static_cast<std::int64_t>(t0_ns + static_cast<double>(cycle * period + std::llround(t_s * kFs)) * 1e9 / kFs);
  };
  std::int64_t cycle = 0;
  while (due_ns(cycle, codes.front().t_s) < now_ns() + 1'500'000'000) ++cycle;
  for (const auto& t : codes) {
    const std::int64_t due = due_ns(cycle, t.t_s);
    sleep_until_ns(due - 300'000'000);  // sent ahead; eicald applies it at its sample
    ASSERT_TRUE(nc.trigger(t.code, due)) << "M" << t.code << " refused or unanswered";
  }

  std::optional<drivers::dds::ResultMsg> result;
  const auto end = std::chrono::steady_clock::now() + 90s;
  while (!result && std::chrono::steady_clock::now() < end) result = nc.bus().take_result(200ms);
  ASSERT_TRUE(result) << "no Result; log:\n" << slurp(dir / "eicald.log");
  std::optional<drivers::dds::TraceMsg> trace;
  for (int i = 0; i < 50 && !(trace && trace->program_id == result->program_id); ++i)
    trace = nc.bus().take_trace(200ms);

  eicald.signal(SIGTERM);
  EXPECT_EQ(eicald.wait_exit(15s), std::optional<int>(0)) << "eicald did not stop cleanly on SIGTERM";

  EXPECT_EQ(result->program, "circle");
  EXPECT_FALSE(result->degraded) << result->json;
  const auto dds_json = nlohmann::json::parse(result->json);
  EXPECT_EQ(dds_json["circle"]["revolutions"], 2);
  const fs::path run = hc.recording_dir / result->program_id;
  ASSERT_TRUE(fs::exists(run / "run.toml")) << run;
  // --no-suggest: the daemon's result carries no simulated variants; the exit status is the
  // verdict's (0 ok, 2 degraded, 3 not measurable; 1 would be an error).
  const auto analyzed = run_capture({EICAL_CLI, "analyze", run.string(), "--json", "--no-suggest"}, 120s, &rc);
  ASSERT_TRUE(analyzed && (rc == 0 || rc == 2 || rc == 3)) << "eical analyze failed with " << rc;
  int differences = 0;
  expect_same(dds_json, nlohmann::json::parse(*analyzed), "", differences);
  EXPECT_EQ(differences, 0);
  EXPECT_DOUBLE_EQ(result->circular_deviation_G_um, dds_json["circle"]["circular_deviation_G_um"].get<double>());

  ASSERT_TRUE(trace && trace->program_id == result->program_id) << "no Trace for " << result->program_id;
  EXPECT_EQ(trace->x_name, "angle_deg");
  EXPECT_EQ(trace->y_name, "radius_deviation_um");
  EXPECT_GT(trace->x.size(), 100u);
  EXPECT_EQ(trace->x.size(), trace->y.size());
  EXPECT_EQ(*std::max_element(trace->series.begin(), trace->series.end()) + 1, 2) << "two revolutions expected";
  // The plotted deviations span exactly G (max − min over all revolutions), up to decimation.
  const auto [lo, hi] = std::minmax_element(trace->y.begin(), trace->y.end());
  EXPECT_LE(*hi - *lo, result->circular_deviation_G_um + 1e-9);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace eical::test
