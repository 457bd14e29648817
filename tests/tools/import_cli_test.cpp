// `eical simulate --export` and `eical import` through the real binary: what a user runs.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>

namespace {

namespace fs = std::filesystem;

struct ImportOutcome {
  int exit_code;
  std::string out, err;
};

ImportOutcome eical(const std::string& args, const fs::path& dir) {
  const fs::path err = dir / "stderr.txt";
  std::string cmd = EICAL_CLI;
  cmd.append(" ").append(args).append(" 2>").append(err.string());
  FILE* p = ::popen(cmd.c_str(), "r");
  std::string out;
  char buf[512];
  while (p && std::fgets(buf, sizeof buf, p)) out += buf;
  const int status = p ? ::pclose(p) : -1;
  std::ifstream is(err);
  return {WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status), out,
          std::string(std::istreambuf_iterator<char>(is), {})};
}

class ImportCli : public ::testing::Test {
 protected:
  void SetUp() override { fs::create_directories(dir_); }
  void TearDown() override { fs::remove_all(dir_); }
  std::string at(const std::string& name) const { return (dir_ / name).string(); }
  fs::path dir_ = fs::temp_directory_path() / ("eical-import-cli-" + std::to_string(std::random_device{}()));
};

TEST_F(ImportCli, SimulatedKlipperTestExportedAndImportedBack) {
  const std::string test = " --freq-start 30 --freq-end 45 --hz-per-sec 2";
  const ImportOutcome sim = eical("simulate --program sweep --sensors head --mems adxl345 --fs 1600" + test +
                                      " --resonance 38,0.03,0.1,x -o " + at("sim") + " --export klipper " +
                                      at("raw.csv") + " --export-offset-s 812.5",
                                  dir_);
  ASSERT_EQ(sim.exit_code, 0) << sim.err;
  EXPECT_NE(sim.out.find("exported"), std::string::npos);
  std::ifstream truth(at("sim") + "/truth.toml");
  const std::string t{std::istreambuf_iterator<char>(truth), {}};
  EXPECT_NE(t.find("[export]"), std::string::npos);
  EXPECT_NE(t.find("[[effects.\"machine.resonance\".modes]]"), std::string::npos);
  const ImportOutcome imp = eical("import klipper " + at("raw.csv") + test + " -o " + at("run"), dir_);
  ASSERT_EQ(imp.exit_code, 0) << imp.err;
  std::printf("%s", imp.out.c_str());
  // The offset found against the one exported, within 3 u (a mode at 38 Hz inside the
  // 30–45 Hz sweep: its phase is taken out with the structure's response).
  const auto at_offset = imp.out.find("time offset recorder - set-point: ");
  ASSERT_NE(at_offset, std::string::npos) << imp.out;
  double offset_s = 0.0, u_us = 0.0;
  ASSERT_EQ(
      std::sscanf(imp.out.c_str() + at_offset, "time offset recorder - set-point: %lf s +- %lf us", &offset_s, &u_us),
      2)
      << imp.out;
  EXPECT_LT(std::abs(offset_s - 812.5), 3.0 * u_us * 1e-6) << imp.out;
  EXPECT_TRUE(fs::exists(at("run") + "/import.toml"));
  EXPECT_TRUE(fs::exists(at("run") + "/samples.csv"));
  // The imported run is a run: analyze reads it (its figures are explain's business). A
  // sweep holds no standstill: no position, so its verdict is not measurable (exit 3, not
  // the 1 of an error).
  EXPECT_EQ(eical("analyze " + at("run") + " --json", dir_).exit_code, 3);
}

TEST_F(ImportCli, BadInputIsOneLineNamingTheCause) {
  ImportOutcome o = eical("import klipper " + at("none.csv") + " -o " + at("run"), dir_);
  EXPECT_EQ(o.exit_code, 1);
  EXPECT_EQ(std::count(o.err.begin(), o.err.end(), '\n'), 1) << o.err;
  EXPECT_NE(o.err.find("no such file"), std::string::npos) << o.err;
  // A capture of another motion than the one described: refused, not aligned to noise.
  ASSERT_EQ(
      eical("simulate --program sweep --sensors head --mems adxl345 --freq-start 30 --freq-end 40 --hz-per-sec 2 -o " +
                at("sim") + " --export klipper " + at("raw.csv"),
            dir_)
          .exit_code,
      0);
  o = eical("import klipper " + at("raw.csv") + " --axis x --freq-start 100 --freq-end 110 -o " + at("run"), dir_);
  EXPECT_EQ(o.exit_code, 1);
  EXPECT_NE(o.err.find("the commanded acceleration is not found in the measured one"), std::string::npos) << o.err;
  o = eical("import klipper " + at("raw.csv") + " --mounting x,x,z -o " + at("run"), dir_);
  EXPECT_EQ(o.exit_code, 1);
  EXPECT_NE(o.err.find("x appears twice"), std::string::npos) << o.err;
}

}  // namespace
