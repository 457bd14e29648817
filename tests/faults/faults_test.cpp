// The fault harness of issue 21: every fault of tests/faults/harness injected into the
// real service, each one test. Each must end in a flagged result or a clean state, with the
// service alive (measuring again) and every completed recording intact.
#include "tests/faults/harness/fault_cases.hpp"

#include <gtest/gtest.h>

#include <cstdio>

namespace eical::faults {
namespace {

void print(const FaultOutcome& o) {
  std::printf("%s -> %s | alive %d flagged %d clean %d | runs before %zu intact %zu after %zu | recovery %.2f s | data lost %s\n",
              o.fault.c_str(), o.outcome.c_str(), o.service_alive, o.flagged, o.clean, o.runs_before, o.runs_intact, o.runs_after,
              o.recovery_s, o.data_lost.c_str());
}

// What every case must show, whatever the fault.
void expect_survived(const FaultOutcome& o) {
  print(o);
  for (const auto& p : o.problems) ADD_FAILURE() << p;
  EXPECT_TRUE(o.service_alive) << "the service did not measure again";
  EXPECT_TRUE(o.flagged || o.clean) << "neither flagged nor clean";
  EXPECT_EQ(o.runs_intact, o.runs_before) << "a completed recording was changed or lost";
}

TEST(Faults, DiskFullMidRecordingIsHeldAndWrittenWhenSpaceReturns) {
  const FaultOutcome o = disk_full_mid_recording();
  expect_survived(o);
  EXPECT_TRUE(o.flagged) << "Status.fault never named the recording";
  EXPECT_TRUE(o.clean);
  EXPECT_EQ(o.measurements_lost, 0);
  EXPECT_LT(o.recovery_s, 5.0);
}

TEST(Faults, RemovedRecordingDirIsMadeAgain) {
  const FaultOutcome o = recording_dir_removed();
  expect_survived(o);
  EXPECT_TRUE(o.clean);
  EXPECT_GE(o.runs_after, 1u);
  EXPECT_EQ(o.measurements_lost, 0);
}

TEST(Faults, WallClockSteppingBackReplacesNoRun) {
  const FaultOutcome o = wall_clock_steps_back();
  expect_survived(o);
  EXPECT_TRUE(o.clean);
  EXPECT_EQ(o.runs_after, 1u);
  EXPECT_EQ(o.measurements_lost, 0);
}

}  // namespace
}  // namespace eical::faults
