// Two threads on one ring: run normally and under ThreadSanitizer (label "threads").
#include "drivers/ring/spsc_ring.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <cstdlib>
#include <string>
#include <thread>

namespace eical::drivers {
namespace {

std::uint64_t stress_items() {
  if (const char* env = std::getenv("EICAL_RING_STRESS_ITEMS")) return std::stoull(env);
#if defined(__SANITIZE_THREAD__)
  return 2'000'000;  // TSan slows every atomic access ~10x; order is what it checks
#else
  // Two spinning threads: under ctest -j2 on two cores they share them with another test,
  // where 10^8 items took minutes; 2·10^7 check the same ordering and wrap-around.
  return 20'000'000;
#endif
}

TEST(SpscRingStress, EveryItemArrivesOnceInOrder) {
  const std::uint64_t n = stress_items();
  SpscRing<std::uint64_t> ring(1024);
  std::thread producer([&] {
    for (std::uint64_t i = 0; i < n; ++i)
      while (!ring.try_push(i)) std::this_thread::yield();
  });
  std::uint64_t expected = 0, bad = 0, v = 0;
  while (expected < n) {
    if (!ring.try_pop(v)) continue;
    bad += v != expected;
    ++expected;
  }
  producer.join();
  EXPECT_EQ(bad, 0u);
  EXPECT_EQ(expected, n);
  EXPECT_EQ(ring.overruns(), 0u);
  EXPECT_FALSE(ring.try_pop(v));
}

TEST(SpscRingStress, DropNewestProducerNeverWaitsAndNothingIsLostUncounted) {
  const std::uint64_t n = stress_items() / 10;
  SpscRing<std::uint64_t> ring(256);
  std::atomic<bool> done{false};
  std::thread producer([&] {
    for (std::uint64_t i = 0; i < n; ++i) (void)ring.push_or_drop(i);
    done.store(true, std::memory_order_release);
  });
  std::uint64_t received = 0, last = 0, not_increasing = 0;
  std::array<std::uint64_t, 64> batch;
  bool first = true;
  for (;;) {
    const bool finished = done.load(std::memory_order_acquire);
    const std::size_t k = ring.pop_many(batch);
    for (std::size_t j = 0; j < k; ++j) {
      not_increasing += !first && batch[j] <= last;
      last = batch[j];
      first = false;
    }
    received += k;
    if (finished && k == 0) break;
  }
  producer.join();
  EXPECT_EQ(not_increasing, 0u);
  EXPECT_EQ(received + ring.overruns(), n);
}

}  // namespace
}  // namespace eical::drivers
