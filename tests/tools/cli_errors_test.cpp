// Bad input at the command line: one line on stderr naming the cause, exit status 1,
// never a crash (a signal would give a different status).
#include "drivers/run_io/run_writer.hpp"
#include "sim/simulate.hpp"

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>

namespace {

namespace fs = std::filesystem;

struct Outcome {
  int exit_code;
  std::string output;
};

Outcome eical(const std::string& args) {
  // Appended piecewise: GCC 12 at -O2 warns falsely (-Warray-bounds) on the chained operator+.
  std::string cmd = EICAL_CLI;
  cmd.append(" ").append(args).append(" 2>&1 >/dev/null");
  FILE* p = ::popen(cmd.c_str(), "r");
  std::string out;
  char buf[512];
  while (p && std::fgets(buf, sizeof buf, p)) out += buf;
  const int status = p ? ::pclose(p) : -1;
  return {WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status), out};
}

void expect_one_line_error(const Outcome& o, const std::string& cause) {
  EXPECT_EQ(o.exit_code, 1) << o.output;
  EXPECT_EQ(std::count(o.output.begin(), o.output.end(), '\n'), 1) << o.output;
  EXPECT_EQ(o.output.rfind("eical: ", 0), 0u) << o.output;
  EXPECT_NE(o.output.find(cause), std::string::npos) << o.output;
}

class CliErrors : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("cli-" + std::to_string(std::random_device{}()));
    eical::drivers::write_run(eical::sim::simulate(eical::sim::circle_scenario(10, 2500, 1)), dir_ / "run");
  }
  void TearDown() override { fs::remove_all(dir_); }
  void edit(const char* file, const std::string& from, const std::string& to) {
    const fs::path p = dir_ / "run" / file;
    std::ifstream is(p);
    std::string s{std::istreambuf_iterator<char>(is), std::istreambuf_iterator<char>()};
    const auto at = s.find(from);
    ASSERT_NE(at, std::string::npos);
    s.replace(at, from.size(), to);
    std::ofstream(p, std::ios::trunc) << s;
  }
  std::string run() const { return (dir_ / "run").string(); }
  fs::path dir_;
};

// A good run: the exit status is its verdict's (0 ok, 2 degraded, 3 not measurable), the
// same the JSON says; never 1, which means an error.
TEST_F(CliErrors, GoodRunExitsWithItsVerdict) {
  const Outcome o = eical("analyze --no-suggest " + run());
  EXPECT_NE(o.output.find(""), std::string::npos);
  std::string cmd = EICAL_CLI;
  cmd.append(" analyze --no-suggest --json ").append(run()).append(" 2>/dev/null");
  FILE* p = ::popen(cmd.c_str(), "r");
  std::string doc;
  char buf[4096];
  while (p && std::fgets(buf, sizeof buf, p)) doc += buf;
  const int status = p ? ::pclose(p) : -1;
  const auto at = doc.find("\"verdict\": \"");
  ASSERT_NE(at, std::string::npos) << doc.substr(0, 400);
  const std::string verdict = doc.substr(at + 12, doc.find('"', at + 12) - at - 12);
  const int expected = verdict == "ok" ? 0 : verdict == "degraded" ? 2 : verdict == "not_measurable" ? 3 : -1;
  ASSERT_NE(expected, -1) << verdict;
  EXPECT_EQ(WIFEXITED(status) ? WEXITSTATUS(status) : -1, expected);
  EXPECT_EQ(o.exit_code, expected);
}

// The one place CLI11's errors become an exit status: a usage error is an error, exit 1,
// one line (CLI11's own codes 105, 106, 109 never leak).
TEST_F(CliErrors, UsageErrorsExitOneWithOneLine) {
  expect_one_line_error(eical("analyze"), "run is required");
  expect_one_line_error(eical("analyze " + run() + " --dynamic sideways"), "--dynamic");
  expect_one_line_error(eical("analyze " + run() + " --no-such-option"), "--no-such-option");
  expect_one_line_error(eical("no-such-command"), "no-such-command");
  expect_one_line_error(eical("simulate --radius -3 -o x"), "--radius");
}

TEST_F(CliErrors, HelpWorks) {
  std::string cmd = EICAL_CLI;
  for (const char* args : {" help", " help analyze", " --help", " analyze --help", " help gen-nc identify"}) {
    FILE* p = ::popen((cmd + args + " 2>&1").c_str(), "r");
    std::string out;
    char buf[512];
    while (p && std::fgets(buf, sizeof buf, p)) out += buf;
    const int status = p ? ::pclose(p) : -1;
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << args << ": " << out;
    if (std::string(args).find("analyze") != std::string::npos) {
      EXPECT_NE(out.find("--calibration"), std::string::npos) << args << ": " << out;
    } else if (std::string(args).find("identify") != std::string::npos) {  // a subcommand's subcommand
      EXPECT_NE(out.find("--swing"), std::string::npos) << args << ": " << out;
    } else {  // the command list: every command, not the help of `help`
      for (const char* c : {"simulate", "analyze", "plan", "identify", "report", "comp", "help"})
        EXPECT_NE(out.find(std::string("  ") + c + " "), std::string::npos)
            << args << " does not list " << c << ": " << out;
    }
  }
  expect_one_line_error(eical("help no-such-command"), "no command 'no-such-command'");
  expect_one_line_error(eical("help gen-nc spiral"), "no command 'spiral' under 'eical gen-nc'");
}

// eical identify on a run that cannot identify the sensors (a circle without strips): one
// line naming the cause, exit 1, and no calibration file.
TEST_F(CliErrors, IdentifyRefusesACircleAndWritesNoCalibration) {
  const fs::path cal = dir_ / "cal.toml";
  expect_one_line_error(eical("identify " + run() + " -o " + cal.string()), "has no PSD strips");
  EXPECT_FALSE(fs::exists(cal));
}

TEST_F(CliErrors, MissingRun) {
  expect_one_line_error(eical("analyze " + (dir_ / "nope").string()), "not a run directory");
}

TEST_F(CliErrors, MissingColumn) {
  edit("samples.csv", "head_az", "head_azz");
  expect_one_line_error(eical("analyze " + run()), "'head_az' is missing");
}

TEST_F(CliErrors, NaNInASample) {
  edit("samples.csv", "\n0.0001,", "\nnan,");
  expect_one_line_error(eical("analyze " + run()), "samples.csv:3: column 't'");
}

TEST_F(CliErrors, TruncatedRun) {
  const fs::path p = dir_ / "run" / "samples.csv";
  fs::resize_file(p, fs::file_size(p) - 7);
  expect_one_line_error(eical("report " + run()), "truncated");
}

TEST_F(CliErrors, WrongTypeInRunToml) {
  edit("run.toml", "adc_bits = 24", "adc_bits = \"24\"");
  expect_one_line_error(eical("analyze " + run()), "acquisition.adc_bits: expected an integer, got string");
}

// A report may be signed already: writing over it takes --force. (One report is rendered:
// the refusal comes before the run is read.)
TEST_F(CliErrors, ReportOverAnExistingReportNeedsForce) {
  const fs::path rep = dir_ / "rep";
  fs::create_directories(rep);
  std::ofstream(rep / "report.html") << "signed\n";
  expect_one_line_error(eical("report " + run() + " -o " + rep.string()),
                        "holds a report already (--force to replace it)");
  std::ifstream kept(rep / "report.html");
  EXPECT_EQ(std::string(std::istreambuf_iterator<char>(kept), std::istreambuf_iterator<char>()), "signed\n");
  EXPECT_EQ(eical("report " + run() + " -o " + rep.string() + " --force").exit_code, 0);
  EXPECT_GT(fs::file_size(rep / "report.html"), 1000u);
}

}  // namespace
