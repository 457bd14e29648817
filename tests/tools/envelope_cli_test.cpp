// The machine's work envelope at the command line (issue 32): gen-nc, simulate and plan
// refuse a program beyond it with one line naming the limit, the value and the option,
// before anything large is allocated; simulate refuses a program longer than its budget;
// plan stops at its deadline and says what it did not evaluate; the envelope reaches
// run.toml and comes back from it, read strictly.
#include "drivers/run_io/run_reader.hpp"
#include "drivers/run_io/run_writer.hpp"
#include "dsp/core/error.hpp"
#include "tests/support/text_file.hpp"

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>

namespace {

namespace fs = std::filesystem;

struct EnvelopeOutcome {
  int exit_code = -1;
  std::string out, err;
  double wall_s = 0.0;
};

using test_support::slurp;

class EnvelopeCli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("envelope-" + std::to_string(std::random_device{}()));
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  // `eical ARGS` as a child process: its exit status, standard output and error apart.
  EnvelopeOutcome eical(const std::string& args) const {
    std::string cmd = EICAL_CLI;
    cmd.append(" ").append(args).append(" >").append((dir_ / "out.txt").string());
    cmd.append(" 2>").append((dir_ / "err.txt").string());
    const auto t0 = std::chrono::steady_clock::now();
    const int status = std::system(cmd.c_str());
    EnvelopeOutcome o;
    o.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    o.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    o.out = slurp(dir_ / "out.txt"), o.err = slurp(dir_ / "err.txt");
    return o;
  }
  fs::path dir_;
};

// One line on stderr, exit status 1, naming every part of `causes`.
void expect_refusal(const EnvelopeOutcome& o, const std::vector<std::string>& causes) {
  EXPECT_EQ(o.exit_code, 1) << o.err;
  EXPECT_EQ(std::count(o.err.begin(), o.err.end(), '\n'), 1) << o.err;
  for (const auto& c : causes) EXPECT_NE(o.err.find(c), std::string::npos) << "missing '" << c << "' in: " << o.err;
}

TEST_F(EnvelopeCli, GenNcRefusesACircleBeyondTheXTravel) {
  const EnvelopeOutcome o = eical("gen-nc circle --radius 1e9");
  expect_refusal(o, {"gen-nc circle: the program reaches x = 1000000000 mm", "beyond the x travel -500..500 mm",
                     "--travel-x", "[envelope] travel_x_mm"});
  EXPECT_EQ(o.out, "");  // nothing written
}

TEST_F(EnvelopeCli, GenNcTakesTheTravelFromItsOptions) {
  // R400 reaches y = 400: beyond the default y travel, within the one given.
  expect_refusal(eical("gen-nc circle --radius 400"), {"y = 400 mm", "beyond the y travel -300..300 mm", "--travel-y"});
  const EnvelopeOutcome o = eical("gen-nc circle --radius 400 --travel-y -450,450");
  EXPECT_EQ(o.exit_code, 0) << o.err;
  EXPECT_NE(o.out.find("G3"), std::string::npos);
}

TEST_F(EnvelopeCli, GenNcRefusesAFeedBeyondTheMaximumFeed) {
  expect_refusal(
      eical("gen-nc step --targets 0,400 --feed 50000"),
      {"gen-nc step: the program moves at 50000 mm/min", "beyond the maximum feed 30000 mm/min", "--max-feed"});
  EXPECT_EQ(eical("gen-nc step --targets 0,400 --feed 50000 --max-feed 60000").exit_code, 0);
}

TEST_F(EnvelopeCli, GenNcRefusesAnAccelerationBeyondTheMaximum) {
  // The interpolator accelerates the path at up to 2 m/s²: a machine of 0.5 m/s² cannot
  // run the circle's moves.
  expect_refusal(eical("gen-nc circle --max-accel 500"),
                 {"gen-nc circle: the program accelerates at", "beyond the maximum acceleration 500 mm/s^2",
                  "--max-accel", "[envelope] max_accel_mm_s2"});
  EXPECT_EQ(eical("gen-nc circle --max-accel 2000").exit_code, 0);
}

TEST_F(EnvelopeCli, GenNcRefusesRepeatsWithoutBound) {
  const EnvelopeOutcome o = eical("gen-nc circle --repeats 2000000000");
  EXPECT_EQ(o.exit_code, 1) << o.err;
  EXPECT_NE(o.err.find("--repeats"), std::string::npos) << o.err;
}

TEST_F(EnvelopeCli, SimulateRefusesACircleBeyondTheEnvelopeBeforeSimulating) {
  const EnvelopeOutcome o = eical("simulate --radius 100000 -o " + (dir_ / "run").string());
  expect_refusal(o, {"simulate circle: the program reaches x = 100000 mm", "beyond the x travel", "--travel-x"});
  EXPECT_LT(o.wall_s, 10.0);
  EXPECT_FALSE(fs::exists(dir_ / "run"));
}

TEST_F(EnvelopeCli, SimulateRefusesAProgramLongerThanItsBudget) {
  // R100 at 1 mm/min: within the travel, but 52 hours long.
  const EnvelopeOutcome o = eical("simulate --radius 100 --feed 1 -o " + (dir_ / "run").string());
  expect_refusal(o, {"simulate: the program runs", "beyond the longest simulation of 2400 s", "--max-duration"});
  EXPECT_LT(o.wall_s, 10.0);
  // A budget below a short program's length refuses it too.
  expect_refusal(eical("simulate --repeats 1 --max-duration 1 -o " + (dir_ / "run").string()),
                 {"beyond the longest simulation of 1 s"});
}

TEST_F(EnvelopeCli, SimulateRefusesASweepLongerThanItsBound) {
  const EnvelopeOutcome o = eical("simulate --program sweep --hz-per-sec 0.0001 -o " + (dir_ / "run").string());
  EXPECT_EQ(o.exit_code, 1) << o.err;
  EXPECT_NE(o.err.find("hz_per_sec: the sweep from freq_start to freq_end would run 1950000 s"), std::string::npos)
      << o.err;
}

TEST_F(EnvelopeCli, SimulateWritesTheEnvelopeIntoRunToml) {
  const EnvelopeOutcome o =
      eical("simulate --repeats 1 --radius 5 --travel-x -600,600 --max-feed 24000 -o " + (dir_ / "run").string());
  ASSERT_EQ(o.exit_code, 0) << o.err;
  const auto meta = eical::drivers::read_run_meta(dir_ / "run" / "run.toml");
  ASSERT_TRUE(meta.envelope.has_value());
  EXPECT_DOUBLE_EQ(meta.envelope->travel_mm[0][0], -600.0);
  EXPECT_DOUBLE_EQ(meta.envelope->travel_mm[0][1], 600.0);
  EXPECT_DOUBLE_EQ(meta.envelope->travel_mm[1][1], eical::dsp::WorkEnvelope{}.travel_mm[1][1]);
  EXPECT_DOUBLE_EQ(meta.envelope->max_feed_mm_min, 24000.0);
  EXPECT_DOUBLE_EQ(meta.envelope->max_accel_mm_s2, eical::dsp::WorkEnvelope{}.max_accel_mm_s2);
}

TEST_F(EnvelopeCli, EnvelopeFileIsReadFromARunToml) {
  eical::dsp::RunMeta meta;
  meta.envelope = eical::dsp::WorkEnvelope{};
  meta.envelope->travel_mm[1][0] = -500.0, meta.envelope->travel_mm[1][1] = 500.0;
  const fs::path toml = dir_ / "machine.toml";
  std::ofstream(toml) << eical::drivers::run_toml_text(meta);
  expect_refusal(eical("gen-nc circle --radius 450"), {"y = 450 mm", "beyond the y travel -300..300 mm"});
  EXPECT_EQ(eical("gen-nc circle --radius 450 --envelope " + toml.string()).exit_code, 0);
  // An option over the file: the file's y travel, the option's x travel.
  expect_refusal(eical("gen-nc circle --radius 450 --envelope " + toml.string() + " --travel-x -400,400"),
                 {"x = 450 mm", "beyond the x travel -400..400 mm"});
  // A file without [envelope] is named.
  std::ofstream(dir_ / "empty.toml") << "x = 1\n";
  expect_refusal(eical("gen-nc circle --envelope " + (dir_ / "empty.toml").string()), {"no [envelope] table"});
}

TEST_F(EnvelopeCli, PlanRefusesACircleBeyondTheEnvelope) {
  const EnvelopeOutcome o = eical("plan --radius 100000");
  expect_refusal(o, {"plan circle: the program reaches x = 100000 mm", "--travel-x"});
  EXPECT_LT(o.wall_s, 10.0);
}

TEST_F(EnvelopeCli, PlanRefusesATestLongerThanItsMaxDuration) {
  const EnvelopeOutcome o = eical("plan --radius 200 --repeats 10");  // 10 revolutions at 2.5 m/min: 302 s
  expect_refusal(o, {"plan circle: the test runs", "longer than the 180 s plan simulates (--max-duration"});
  EXPECT_LT(o.wall_s, 10.0);
}

TEST_F(EnvelopeCli, PlanStopsAtItsDeadlineAndSaysWhatItDidNotEvaluate) {
  // R25 twice is not measurable (tests/uncertainty): variants would follow; a deadline of
  // 0 s lets none start.
  const EnvelopeOutcome o = eical("plan --radius 25 --repeats 2 --draws 20 --deadline 0");
  EXPECT_EQ(o.exit_code, 6) << o.err;  // kExitIncomplete
  EXPECT_NE(o.err.find("plan: simulating the test: circle R25"), std::string::npos) << o.err;
  EXPECT_NE(o.err.find("the deadline of 0 s passed"), std::string::npos) << o.err;
  EXPECT_EQ(o.err.find("variant 1 of"), std::string::npos) << o.err;    // none started
  EXPECT_NE(o.out.find("NOT MEASURABLE"), std::string::npos) << o.out;  // the test itself was evaluated
  EXPECT_NE(o.out.find("NOT EVALUATED: the deadline passed"), std::string::npos) << o.out;
}

TEST_F(EnvelopeCli, PlanShowsItsProgressOnStderr) {
  // With time for them, the variants are announced one by one.
  const EnvelopeOutcome o = eical("plan --radius 25 --repeats 2 --draws 10 --max-duration 20 --deadline 600");
  EXPECT_EQ(o.exit_code, 0) << o.err;
  EXPECT_NE(o.err.find("variant 1 of"), std::string::npos) << o.err;
  EXPECT_EQ(o.err.find("deadline"), std::string::npos) << o.err;
}

TEST(RunMetaEnvelope, RoundTripsThroughRunToml) {
  eical::dsp::RunMeta meta;
  meta.id = "envelope";
  meta.envelope = eical::dsp::WorkEnvelope{};
  meta.envelope->travel_mm[2][0] = -450.5, meta.envelope->max_accel_mm_s2 = 4000.0;
  const fs::path p = fs::temp_directory_path() / ("envelope-" + std::to_string(std::random_device{}()) + ".toml");
  std::ofstream(p) << eical::drivers::run_toml_text(meta);
  const auto back = eical::drivers::read_run_meta(p);
  fs::remove(p);
  ASSERT_TRUE(back.envelope.has_value());
  EXPECT_DOUBLE_EQ(back.envelope->travel_mm[2][0], -450.5);
  EXPECT_DOUBLE_EQ(back.envelope->max_accel_mm_s2, 4000.0);
  // A run without [envelope] has none (runs written before it).
  meta.envelope.reset();
  std::ofstream(p) << eical::drivers::run_toml_text(meta);
  EXPECT_FALSE(eical::drivers::read_run_meta(p).envelope.has_value());
  fs::remove(p);
}

TEST(RunMetaEnvelope, IsReadStrictlyInRunToml) {
  eical::dsp::RunMeta meta;
  meta.id = "envelope";
  std::string text = eical::drivers::run_toml_text(meta) + "\n[envelope]\nmax_feed_mm_mn = 20000\n";
  const fs::path p = fs::temp_directory_path() / ("envelope-" + std::to_string(std::random_device{}()) + ".toml");
  std::ofstream(p) << text;
  try {
    (void)eical::drivers::read_run_meta(p);
    ADD_FAILURE() << "an unknown key in [envelope] was accepted";
  } catch (const eical::dsp::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("envelope.max_feed_mm_mn"), std::string::npos) << e.what();
  }
  std::ofstream(p, std::ios::trunc) << eical::drivers::run_toml_text(meta) << "\n[envelope]\nmax_accel_mm_s2 = -1\n";
  try {
    (void)eical::drivers::read_run_meta(p);
    ADD_FAILURE() << "a negative acceleration was accepted";
  } catch (const eical::dsp::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("envelope.max_accel_mm_s2"), std::string::npos) << e.what();
  }
  fs::remove(p);
}

}  // namespace
