// `eicald --check` on this machine, as a machine builder runs it before the first start:
// every problem is one line naming its cause (absent DAQ, absent trigger devices, an
// unwritable recording path, a missing DDS configuration, a missing program directory),
// exit 3; a sound configuration says so, exit 0.
#include "child_process.hpp"
#include "hil_support.hpp"

namespace eical::test {
namespace {

std::pair<std::optional<int>, std::string> check(const fs::path& config) {
  const fs::path log = config.parent_path() / "check.log";
  std::optional<int> rc;
  {
    ChildProcess p({EICALD_BIN, "--check", "--config", config.string()}, log.string());
    rc = p.wait_exit(60s);
  }
  return {rc, slurp(log)};
}

TEST(HilCheck, NamesEveryProblemOfTheMachine) {
  const fs::path dir = scratch_dir("check-bad");
  std::ofstream(dir / "eicald.toml") << "[source]\nkind = \"usb_daq\"\n"
                                     << "[setpoint]\nsource = \"program\"\n[setpoint.program]\ndirectory = \""
                                     << (dir / "no-programs").string() << "\"\n"
                                     << "[triggers]\ninputs = [\"frame\", \"gpio\", \"can\"]\ngpio_chip = "
                                        "\"gpiochip-absent\"\ncan_interface = \"can-absent\"\n"
                                     << "[dds]\nconfig_uri = \"file://" << (dir / "missing.xml").string() << "\"\n"
                                     << "[recording]\ndir = \"/proc/nope/runs\"\n";
  const auto [rc, out] = check(dir / "eicald.toml");
  EXPECT_EQ(rc, std::optional<int>(3)) << out;
  for (const std::string& want :
       {std::string("usb_daq: no DAQ with USB id 1d50:6161"), std::string("gpio: cannot open gpiochip-absent"),
        std::string("can: "), std::string("/proc/nope/runs"),
        (dir / "missing.xml").string() + " ([dds] config_uri) does not exist",
        "the program directory " + (dir / "no-programs").string() + " does not exist"})
    EXPECT_NE(out.find(want), std::string::npos) << "missing: " << want << "\n" << out;
  fs::remove_all(dir);
}

TEST(HilCheck, ASoundConfigurationIsValid) {
  const fs::path dir = scratch_dir("check-good");
  HilConfig hc;
  hc.domain = hil_domain(8);
  int rc = -1;
  ASSERT_TRUE(run_capture({EICAL_CLI, "gen-nc", "circle", "--radius", "10", "--feed", "2500", "--repeats", "1", "-o",
                           (dir / "circle.ngc").string(), "--meta", (dir / "circle.toml").string()},
                          30s, &rc));
  hc.program_file = dir / "circle.toml";
  hc.recording_dir = dir / "runs";
  const auto [code, out] = check(write_config(dir, hc));
  EXPECT_EQ(code, std::optional<int>(0)) << out;
  EXPECT_NE(out.find("configuration valid; source 'sim' opens"), std::string::npos) << out;
  EXPECT_TRUE(fs::is_directory(dir / "runs")) << "the recording path is made and probed";
  fs::remove_all(dir);
}

}  // namespace
}  // namespace eical::test
