// The measurement's guards around the real eicald and eical binaries: an M101 sent during
// a measurement is refused with its reason on Reply and the measurement goes on untouched
// (one recording, one M101 mark, not degraded); `eical hmi` never shows a result count
// below a result it printed; without a daemon it says so and exits non-zero.
#include "child_process.hpp"
#include "drivers/run_io/run_reader.hpp"
#include "hil_support.hpp"

#include <nlohmann/json.hpp>

#include <sstream>

namespace eical::test {
namespace {

TEST(HilGuards, M101DuringAMeasurementIsRefusedOnReplyAndTheMeasurementContinues) {
  const fs::path dir = scratch_dir("guards");
  int rc = -1;
  ASSERT_TRUE(run_capture({EICAL_CLI, "gen-nc", "circle", "--radius", "10", "--feed", "2500", "--repeats", "1", "-o",
                           (dir / "circle.ngc").string(), "--meta", (dir / "circle.toml").string()},
                          30s, &rc));
  ASSERT_EQ(rc, 0);
  HilConfig hc;
  hc.domain = hil_domain(4);
  hc.program_file = dir / "circle.toml";
  hc.recording_dir = dir / "runs";
  const fs::path cfg = write_config(dir, hc);
  ChildProcess eicald({EICALD_BIN, "--config", cfg.string()}, (dir / "eicald.log").string());
  // The HMI, as a machine operator runs it, from before the first result.
  // It listens 12 s: the result arrives after about 4 s, and Status (1 Hz) keeps coming.
  ChildProcess hmi({EICAL_CLI, "hmi", "--domain", std::to_string(hc.domain), "--timeout", "12"},
                   (dir / "hmi.log").string());
  NcOnBus nc(hc.domain);
  ASSERT_TRUE(nc.handshake(30s)) << slurp(dir / "eicald.log");
  ASSERT_TRUE(nc.trigger(101, now_ns()));
  ASSERT_TRUE(nc.status(10s, [](const drivers::dds::StatusMsg& s) { return s.state == "MEASURING"; }))
      << slurp(dir / "eicald.log");
  const auto refused = nc.trigger_reply(101, now_ns(), 3.0);
  ASSERT_TRUE(refused) << "no Reply to the second M101";
  EXPECT_FALSE(refused->ok);
  EXPECT_NE(refused->message.find("refused: a measurement is running"), std::string::npos) << refused->message;
  EXPECT_NE(refused->message.find("continues untouched"), std::string::npos) << refused->message;
  EXPECT_EQ(refused->state, "MEASURING");
  std::this_thread::sleep_for(1s);
  ASSERT_TRUE(nc.trigger(103, now_ns()));
  const auto hmi_rc = hmi.wait_exit(30s);
  eicald.signal(SIGTERM);
  EXPECT_EQ(eicald.wait_exit(20s), std::optional<int>(0)) << slurp(dir / "eicald.log");
  EXPECT_EQ(hmi_rc, std::optional<int>(0)) << slurp(dir / "hmi.log");

  std::vector<fs::path> runs;
  for (const auto& e : fs::directory_iterator(hc.recording_dir)) runs.push_back(e.path());
  ASSERT_EQ(runs.size(), 1u) << "the refused M101 must not split the measurement";
  const auto run = drivers::read_run(runs[0]);
  int starts = 0;
  std::int64_t i101 = -1, i103 = -1;
  for (const auto& f : run.frames) {
    if (f.trigger == 101) ++starts, i101 = f.sample_index;
    if (f.trigger == 103) i103 = f.sample_index;
  }
  EXPECT_EQ(starts, 1);
  // The whole measurement from the first M101 to the M103 (> 1 s), not the part after the
  // refused M101.
  ASSERT_GE(i101, 0);
  ASSERT_GT(i103, i101);
  EXPECT_GT(static_cast<double>(i103 - i101) / run.fs_hz(), 1.0);
  const auto j = nlohmann::json::parse(slurp(runs[0] / "result.json"));
  for (const auto& c : j["quality"]["flag_codes"]) {
    EXPECT_NE(c, "interrupted") << j["quality"]["flags"].dump();
    EXPECT_NE(c, "no_start_trigger") << j["quality"]["flags"].dump();
  }

  // The HMI's status lines after the result it printed count it.
  std::istringstream log(slurp(dir / "hmi.log"));
  bool after_result = false;
  int status_after = 0;
  for (std::string line; std::getline(log, line);) {
    if (line.rfind("result ", 0) == 0) after_result = true;
    unsigned long long n = 0;
    const auto at = line.find(" lost, ");
    if (after_result && line.rfind("status ", 0) == 0 && at != std::string::npos &&
        std::sscanf(line.c_str() + at, " lost, %llu results", &n) == 1) {
      EXPECT_GE(n, 1u) << line;
      ++status_after;
    }
  }
  EXPECT_TRUE(after_result) << slurp(dir / "hmi.log");
  EXPECT_GE(status_after, 2) << slurp(dir / "hmi.log");
  fs::remove_all(dir);
}

TEST(HilGuards, HmiWithoutADaemonSaysSoAndExitsNonZero) {
  const int domain = hil_domain(5);
  int rc = -1;
  const auto t0 = std::chrono::steady_clock::now();
  char tmpl[] = "/tmp/eical-hil-err-XXXXXX";
  const int fd = ::mkstemp(tmpl);
  ASSERT_GE(fd, 0);
  ::close(fd);
  std::optional<int> exit;
  {
    ChildProcess hmi({EICAL_CLI, "hmi", "--domain", std::to_string(domain), "--timeout", "2"}, tmpl);
    exit = hmi.wait_exit(20s);
  }
  const std::string out = slurp(tmpl);
  std::remove(tmpl);
  (void)rc;
  ASSERT_TRUE(exit) << "eical hmi did not exit after its timeout";
  EXPECT_NE(*exit, 0);
  EXPECT_NE(out.find("no eicald on DDS domain " + std::to_string(domain)), std::string::npos) << out;
  EXPECT_LT(std::chrono::steady_clock::now() - t0, 15s);
}

}  // namespace
}  // namespace eical::test
