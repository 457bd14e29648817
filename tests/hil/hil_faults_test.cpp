// Faults around the real eicald process: SIGTERM in the middle of a measurement (what was
// recorded so far is saved and flagged `interrupted`, never a half-written directory) and
// an HMI that disappears and returns (the Result of what was measured meanwhile still
// arrives: transient-local).
#include "child_process.hpp"
#include "drivers/run_io/run_reader.hpp"
#include "hil_support.hpp"

#include <nlohmann/json.hpp>

namespace eical::test {
namespace {

struct Daemon {
  fs::path dir;
  HilConfig hc;
  std::unique_ptr<ChildProcess> process;
  std::string log() const { return slurp(dir / "eicald.log"); }
};

Daemon start_daemon(const std::string& tag, int salt) {
  Daemon d;
  d.dir = scratch_dir(tag);
  int rc = -1;
  const auto out = run_capture({EICAL_CLI, "gen-nc", "circle", "--radius", "10", "--feed", "2500", "--repeats", "2",
                                "-o", (d.dir / "circle.ngc").string(), "--meta", (d.dir / "circle.toml").string()},
                               30s, &rc);
  EXPECT_TRUE(out && rc == 0) << "eical gen-nc failed";
  d.hc.domain = hil_domain(salt);
  d.hc.program_file = d.dir / "circle.toml";
  d.hc.recording_dir = d.dir / "runs";
  const fs::path cfg = write_config(d.dir, d.hc);
  d.process = std::make_unique<ChildProcess>(std::vector<std::string>{EICALD_BIN, "--config", cfg.string()},
                                             (d.dir / "eicald.log").string());
  return d;
}

std::vector<fs::path> entries(const fs::path& dir) {
  std::vector<fs::path> out;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir, ec)) out.push_back(e.path());
  return out;
}

TEST(HilFaults, SigtermDuringAMeasurementSavesItFlaggedInterrupted) {
  Daemon d = start_daemon("sigterm", 2);
  NcOnBus nc(d.hc.domain);
  ASSERT_TRUE(nc.handshake(30s)) << d.log();
  ASSERT_TRUE(nc.trigger(101, now_ns()));
  ASSERT_TRUE(nc.status(10s, [](const drivers::dds::StatusMsg& s) { return s.state == "MEASURING"; })) << d.log();
  std::this_thread::sleep_for(1500ms);  // part of a measurement, no M103
  d.process->signal(SIGTERM);
  const auto rc = d.process->wait_exit(20s);
  ASSERT_TRUE(rc) << "eicald did not exit after SIGTERM";
  EXPECT_EQ(*rc, 0) << d.log();
  const auto all = entries(d.hc.recording_dir);
  ASSERT_EQ(all.size(), 1u) << "exactly the interrupted run expected (no temporaries)";
  EXPECT_NE(all[0].filename().string()[0], '.') << "a temporary directory was left: " << all[0];
  EXPECT_NO_THROW((void)drivers::read_run(all[0]));
  ASSERT_TRUE(fs::exists(all[0] / "result.json")) << d.log();
  const auto j = nlohmann::json::parse(slurp(all[0] / "result.json"));
  EXPECT_TRUE(j["quality"]["degraded"].get<bool>());
  bool interrupted = false;
  for (const auto& c : j["quality"]["flag_codes"]) interrupted |= c == "interrupted";
  EXPECT_TRUE(interrupted) << j["quality"]["flags"].dump();
  fs::remove_all(d.dir);
}

TEST(HilFaults, HmiThatLeftAndReturnsGetsTheResultMeasuredMeanwhile) {
  Daemon d = start_daemon("hmi", 3);
  std::int64_t sent_101 = 0;
  {
    NcOnBus nc(d.hc.domain);  // NC and HMI share this participant; it goes away below
    ASSERT_TRUE(nc.handshake(30s)) << d.log();
    sent_101 = now_ns();
    ASSERT_TRUE(nc.trigger(101, sent_101));
    std::this_thread::sleep_for(1s);
    ASSERT_TRUE(nc.trigger(103, now_ns()));
  }  // the HMI disappears before the result exists
  // The result is written while no HMI is connected.
  const auto end = std::chrono::steady_clock::now() + 60s;
  fs::path run;
  while (run.empty() && std::chrono::steady_clock::now() < end) {
    for (const auto& e : entries(d.hc.recording_dir))
      if (fs::exists(e / "result.json")) run = e;
    std::this_thread::sleep_for(100ms);
  }
  ASSERT_FALSE(run.empty()) << d.log();
  EXPECT_TRUE(d.process->running()) << "eicald stopped while the HMI was away";
  drivers::dds::Bus hmi(d.hc.domain, drivers::dds::Role::hmi);  // the HMI returns
  std::optional<drivers::dds::ResultMsg> result;
  const auto until = std::chrono::steady_clock::now() + 20s;
  while (!(result && result->program_id == run.filename().string()) && std::chrono::steady_clock::now() < until)
    result = hmi.take_result(200ms);
  ASSERT_TRUE(result && result->program_id == run.filename().string())
      << "the returning HMI did not get " << run.filename();
  EXPECT_EQ(nlohmann::json::parse(result->json)["format"], "eical-result/1");
  d.process->signal(SIGTERM);
  EXPECT_EQ(d.process->wait_exit(20s), std::optional<int>(0));
  fs::remove_all(d.dir);
}

}  // namespace
}  // namespace eical::test
