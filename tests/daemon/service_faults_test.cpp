// Faults injected into eicald's service loop (sim backend, free-running): frames lost, a
// channel saturated, a channel NaN, the source failing mid-run, the recording path full or
// unwritable. Each must end in a flagged result or a reported error, the service going on,
// and every completed recording intact (readable, result.json unchanged).
#include "daemon/service/service.hpp"
#include "drivers/dds/domain_claim.hpp"
#include "drivers/run_io/run_reader.hpp"
#include "sim/gcode/generate.hpp"
#include "sim/nc/trajectory.hpp"
#include "sim/scenario.hpp"

#include <gtest/gtest.h>
#include <sys/resource.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <random>
#include <thread>

namespace {

namespace fs = std::filesystem;
using eical::daemon::DaemonConfig;
using eical::daemon::Service;
using eical::daemon::ServiceStatus;
using namespace std::chrono_literals;

DaemonConfig base_config(const fs::path& dir) {
  DaemonConfig c;
  c.source.pacing = "free_running";
  c.source.sim_repeats = 2;
  c.source.sim_repeat_program = false;
  c.triggers.inputs = {"frame"};  // no HMI bus needed here
  c.dds.domain_id = eical::drivers::dds::claim_free_domain();
  c.dds.config_uri = "file://" EICAL_SOURCE_DIR "/config/cyclonedds-loopback.xml";
  c.recording.dir = dir;
  c.recording.gzip = false;
  c.realtime.sched_fifo_priority = 0;
  c.realtime.mlockall = false;
  c.limits.max_measurement_s = 30.0;
  c.source.retry_s = 0.2;
  return c;
}

// Middle of the measurement (between M101 and M103) of the configured circle, in s.
double mid_measurement_s(const DaemonConfig& c) {
  const auto sc = eical::sim::circle_scenario(c.source.sim_radius_mm, c.source.sim_feed_mm_min, c.source.sim_repeats);
  const auto tr =
      eical::sim::nc::interpolate_gcode(eical::sim::gcode::program_gcode(sc.meta.program), "circle", sc.limits);
  double t101 = -1, t103 = -1;
  for (const auto& t : tr.triggers()) {
    if (t.code == 101 && t101 < 0) t101 = t.t_s;
    if (t.code == 103) t103 = t.t_s;
  }
  return 0.5 * (t101 + t103);
}

fs::path scratch(const std::string& tag) {
  return fs::temp_directory_path() / ("eicald-fault-" + tag + "-" + std::to_string(std::random_device{}()));
}

// Run directories (hidden temporaries excluded), oldest sample first.
std::vector<fs::path> runs_in(const fs::path& dir) {
  std::vector<fs::path> out;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir, ec))
    if (e.is_directory() && e.path().filename().string()[0] != '.') out.push_back(e.path());
  auto index = [](const fs::path& p) {
    return std::stoll(p.filename().string().substr(p.filename().string().rfind('-') + 1));
  };
  std::sort(out.begin(), out.end(), [&](const fs::path& a, const fs::path& b) { return index(a) < index(b); });
  return out;
}

nlohmann::json result_of(const fs::path& run) {
  std::ifstream is(run / "result.json");
  return nlohmann::json::parse(is);
}

// By the flag's code (result-format.md, "Quality flags").
bool has_flag(const nlohmann::json& j, const std::string& code) {
  for (const auto& c : j["quality"]["flag_codes"])
    if (c == code) return true;
  return false;
}

std::string read_bytes(const fs::path& p) {
  std::ifstream is(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(is), std::istreambuf_iterator<char>()};
}

// Runs the service until its (non-repeating) source ends; returns the last status.
ServiceStatus run_to_end(const DaemonConfig& c) {
  std::atomic<bool> stop{false};
  ServiceStatus last;
  Service(c).run(stop, [&](const ServiceStatus& s) { last = s; });
  return last;
}

struct FaultCase {
  const char* name;
  void (*inject)(eical::drivers::FaultPlan&, double mid_s);
  const char* flag;
};

class InjectedFault : public ::testing::TestWithParam<FaultCase> {};

TEST_P(InjectedFault, EndsInAFlaggedResultWithTheRecordingIntact) {
  const fs::path dir = scratch(GetParam().name);
  DaemonConfig c = base_config(dir);
  GetParam().inject(c.source.fault, mid_measurement_s(c));
  const ServiceStatus last = run_to_end(c);
  const auto runs = runs_in(dir);
  ASSERT_EQ(runs.size(), 1u) << "one measurement expected";
  const auto j = result_of(runs[0]);
  EXPECT_TRUE(j["quality"]["degraded"].get<bool>()) << j["quality"].dump();
  EXPECT_TRUE(has_flag(j, GetParam().flag)) << GetParam().flag << " not in " << j["quality"]["flags"].dump();
  EXPECT_NO_THROW((void)eical::drivers::read_run(runs[0])) << "the recording is not readable";
  EXPECT_EQ(last.results_written, 1u);
  EXPECT_TRUE(last.fault.empty()) << last.fault;
  fs::remove_all(dir);
}

void inject_gap(eical::drivers::FaultPlan& p, double at_s) { p.gap_at_s = at_s, p.gap_frames = 500; }
void inject_saturation(eical::drivers::FaultPlan& p, double at_s) { p.saturate_at_s = at_s, p.saturate_s = 0.05; }
void inject_nan(eical::drivers::FaultPlan& p, double at_s) { p.nan_at_s = at_s, p.nan_s = 0.2; }
std::string case_name(const ::testing::TestParamInfo<FaultCase>& c) { return c.param.name; }

INSTANTIATE_TEST_SUITE_P(Faults, InjectedFault,
                         ::testing::Values(FaultCase{"gap", inject_gap, "frames_lost"},
                                           FaultCase{"saturation", inject_saturation, "accel_saturated"},
                                           FaultCase{"nan", inject_nan, "not_finite"}),
                         case_name);

TEST(ServiceFaults, SourceFailureMidRunIsRecordedFlaggedAndTheSourceReopened) {
  const fs::path dir = scratch("source");
  DaemonConfig c = base_config(dir);
  c.source.sim_repeat_program = true;  // after the reopen the program runs again
  c.source.sim_idle_s = 0.2;
  c.source.fault.fail_at_s = mid_measurement_s(c);
  std::atomic<bool> stop{false};
  std::mutex mu;
  bool saw_fault = false;
  std::string fault_text;
  std::thread service([&] {
    Service(c).run(stop, [&](const ServiceStatus& s) {
      std::lock_guard lk(mu);
      if (s.state == "FAULT") saw_fault = true, fault_text = s.fault;
    });
  });
  const auto end = std::chrono::steady_clock::now() + 180s;
  while (std::chrono::steady_clock::now() < end && runs_in(dir).size() < 2) std::this_thread::sleep_for(100ms);
  std::this_thread::sleep_for(200ms);  // let the second result.json land
  stop = true;
  service.join();
  const auto runs = runs_in(dir);
  ASSERT_GE(runs.size(), 2u) << "the service did not measure again after the source failure";
  const auto first = result_of(runs[0]), second = result_of(runs[1]);
  EXPECT_TRUE(first["quality"]["degraded"].get<bool>());
  EXPECT_TRUE(has_flag(first, "source_stopped")) << first["quality"]["flags"].dump();
  EXPECT_FALSE(has_flag(second, "source_stopped")) << second["quality"]["flags"].dump();
  EXPECT_TRUE(second["circle"].is_object()) << "the measurement after the reopen was not evaluated";
  for (const auto& r : runs) EXPECT_NO_THROW((void)eical::drivers::read_run(r)) << r;
  std::lock_guard lk(mu);
  EXPECT_TRUE(saw_fault) << "Status never showed FAULT";
  EXPECT_NE(fault_text.find("injected fault"), std::string::npos) << fault_text;
  fs::remove_all(dir);
}

TEST(ServiceFaults, UnwritableRecordingPathIsReportedAndTheServiceEndsCleanly) {
  const fs::path base = scratch("unwritable");
  fs::create_directories(base);
  std::ofstream(base / "not-a-dir") << "x";  // works as root too, unlike chmod
  DaemonConfig c = base_config(base / "not-a-dir" / "runs");
  const ServiceStatus last = run_to_end(c);
  EXPECT_EQ(last.results_written, 0u);
  EXPECT_NE(last.fault.find("recording"), std::string::npos) << last.fault;
  EXPECT_NE(last.fault.find("not-a-dir"), std::string::npos) << "the error does not name the path: " << last.fault;
  fs::remove_all(base);
}

TEST(ServiceFaults, FullDiskIsReportedAndEarlierRunsStayIntact) {
  const fs::path dir = scratch("full");
  DaemonConfig c = base_config(dir);
  ASSERT_EQ(run_to_end(c).results_written, 1u);
  const auto before = runs_in(dir);
  ASSERT_EQ(before.size(), 1u);
  const std::string samples = read_bytes(before[0] / "samples.csv"), result = read_bytes(before[0] / "result.json");

  // "Disk full" for this process: files may not grow past 64 KiB (EFBIG, like ENOSPC).
  rlimit old{};
  ASSERT_EQ(::getrlimit(RLIMIT_FSIZE, &old), 0);
  auto* old_handler = std::signal(SIGXFSZ, SIG_IGN);
  rlimit small = old;
  small.rlim_cur = 64 * 1024;
  ASSERT_EQ(::setrlimit(RLIMIT_FSIZE, &small), 0);
  c.source.sim_seed = 2;  // another measurement
  const ServiceStatus last = run_to_end(c);
  ::setrlimit(RLIMIT_FSIZE, &old);
  std::signal(SIGXFSZ, old_handler);

  EXPECT_EQ(last.results_written, 0u);
  EXPECT_NE(last.fault.find("recording"), std::string::npos) << last.fault;
  const auto after = runs_in(dir);
  ASSERT_EQ(after.size(), 1u) << "a partial run was left behind";
  EXPECT_EQ(read_bytes(after[0] / "samples.csv"), samples);
  EXPECT_EQ(read_bytes(after[0] / "result.json"), result);
  std::size_t hidden = 0;
  for (const auto& e : fs::directory_iterator(dir)) hidden += e.path().filename().string()[0] == '.';
  EXPECT_EQ(hidden, 0u) << "a temporary directory was left behind";
  fs::remove_all(dir);
}

}  // namespace
