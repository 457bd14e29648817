// Pipeline::step must not allocate: count global allocations around the per-sample loop.
#include "dsp/pipeline/pipeline.hpp"
#include "sim/simulate.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>

namespace {
std::atomic<bool> g_counting{false};
std::atomic<std::size_t> g_allocations{0};
}  // namespace

// Sanitizers replace operator new themselves; the count runs in the plain build only.
#if defined(EICAL_SANITIZED)
#define EICAL_COUNT_ALLOCATIONS 0
#else
#define EICAL_COUNT_ALLOCATIONS 1
// The replacement pair is malloc/free by design; GCC cannot see that new and delete match.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
void* operator new(std::size_t n) {
  if (g_counting.load(std::memory_order_relaxed)) g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
#pragma GCC diagnostic pop
#endif

namespace eical {
namespace {

TEST(PipelineRealTime, StepDoesNotAllocate) {
  if (!EICAL_COUNT_ALLOCATIONS) GTEST_SKIP() << "sanitizer build: allocations are counted in the plain build";
  const dsp::Run run = sim::simulate(sim::circle_scenario(10.0, 2500.0, 1));
  dsp::Pipeline p(dsp::pipeline_config(run.meta, run.frames.size()));
  g_allocations = 0;
  g_counting = true;
  for (const auto& f : run.frames) p.step(f);
  g_counting = false;
  EXPECT_EQ(g_allocations.load(), 0u);
  EXPECT_TRUE(p.live().integrating);
  const auto m = p.finish();  // allowed to allocate
  EXPECT_FALSE(m.pos_mm.empty());
}

}  // namespace
}  // namespace eical
