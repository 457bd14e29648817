#include "drivers/ring/spsc_ring.hpp"
#include "dsp/core/frame.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cstdint>

namespace eical::drivers {
namespace {

TEST(SpscRing, CapacityMustBeAPowerOfTwo) {
  EXPECT_THROW(SpscRing<int>(0), std::invalid_argument);
  EXPECT_THROW(SpscRing<int>(1), std::invalid_argument);
  EXPECT_THROW(SpscRing<int>(1000), std::invalid_argument);
  EXPECT_EQ(SpscRing<int>(1024).capacity(), 1024u);
}

TEST(SpscRing, FifoFullEmptyAndWrapAround) {
  SpscRing<std::uint64_t> ring(8);
  std::uint64_t next_in = 0, next_out = 0, v = 0;
  EXPECT_FALSE(ring.try_pop(v));
  for (int round = 0; round < 1000; ++round) {  // wraps the 8 slots many times
    const int n = 1 + round % 8;
    for (int k = 0; k < n; ++k) ASSERT_TRUE(ring.try_push(next_in++));
    EXPECT_EQ(ring.size_approx(), static_cast<std::size_t>(n));
    for (int k = 0; k < n; ++k) {
      ASSERT_TRUE(ring.try_pop(v));
      ASSERT_EQ(v, next_out++);
    }
    EXPECT_FALSE(ring.try_pop(v));
  }
  for (int k = 0; k < 8; ++k) ASSERT_TRUE(ring.try_push(static_cast<std::uint64_t>(k)));
  EXPECT_FALSE(ring.try_push(99));
}

TEST(SpscRing, FullRingDropsTheNewestAndCountsIt) {
  SpscRing<int> ring(4);
  for (int k = 0; k < 4; ++k) EXPECT_TRUE(ring.push_or_drop(k));
  EXPECT_FALSE(ring.push_or_drop(100));
  EXPECT_FALSE(ring.push_or_drop(101));
  EXPECT_EQ(ring.overruns(), 2u);
  int v = -1;
  for (int k = 0; k < 4; ++k) {  // the older frames are intact, in order
    ASSERT_TRUE(ring.try_pop(v));
    EXPECT_EQ(v, k);
  }
  EXPECT_FALSE(ring.try_pop(v));
}

TEST(SpscRing, PopManyTakesWhatIsThereUpToTheSpan) {
  SpscRing<dsp::Frame> ring(16);
  for (int k = 0; k < 10; ++k) {
    dsp::Frame f;
    f.sample_index = k;
    ASSERT_TRUE(ring.try_push(f));
  }
  std::array<dsp::Frame, 4> out;
  EXPECT_EQ(ring.pop_many(out), 4u);
  EXPECT_EQ(out[3].sample_index, 3);
  std::array<dsp::Frame, 32> rest;
  EXPECT_EQ(ring.pop_many(rest), 6u);
  EXPECT_EQ(rest[5].sample_index, 9);
  EXPECT_EQ(ring.pop_many(rest), 0u);
}

}  // namespace
}  // namespace eical::drivers
