// The simulated DAQ's sample clock (the HIL flake of stop 36): paced in real time, sample k
// is taken at the first read + k / fs, however late a loaded machine lets read() return
// it; an M-code sent for a sample then lands on that sample.
#include "drivers/source/sim_source.hpp"
#include "drivers/source/stamped_source.hpp"
#include "sim/scenario.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <thread>
#include <vector>

namespace eical::drivers {
namespace {

TEST(SimSourceClock, ALateReadStampsItsSamplesWhenTheyWereTakenNotWhenReturned) {
  SimSourceOptions o;
  o.pacing = Pacing::realtime;
  StampedSource src(std::make_unique<SimSource>(sim::step_scenario(0.0, 1.0, 3000.0, 1, 1), o));
  src.open();
  std::vector<dsp::Frame> block(100);
  ASSERT_EQ(src.read(block), block.size());
  const std::int64_t first_ns = src.acquired_ns(block.back().sample_index);
  std::this_thread::sleep_for(std::chrono::milliseconds(80));  // the acquisition thread was starved
  ASSERT_EQ(src.read(block), block.size());
  const std::int64_t second_ns = src.acquired_ns(block.back().sample_index);
  const double fs = src.meta().acquisition.fs_hz;
  // 100 samples later on the DAQ clock, not 80 ms later on the wall clock.
  EXPECT_NEAR(static_cast<double>(second_ns - first_ns), 100.0 / fs * 1e9, 1.0);
  EXPECT_LT(second_ns, monotonic_ns()) << "a sample stamped after it was returned";
}

TEST(SimSourceClock, AnUnpacedSourceLeavesTheStampToTheReader) {
  SimSourceOptions o;
  o.pacing = Pacing::free_running;
  SimSource src(sim::step_scenario(0.0, 1.0, 3000.0, 1, 1), o);
  src.open();
  EXPECT_EQ(src.sample_time_ns(10), 0);
}

}  // namespace
}  // namespace eical::drivers
