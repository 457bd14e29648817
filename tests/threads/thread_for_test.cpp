// The executor the evaluations' independent work runs on (drivers/exec/thread_for.hpp):
// every task exactly once, the caller back only when all have returned, a task's
// exception rethrown after the others finished. Runs under ThreadSanitizer in scripts/test
// (label threads).
#include "drivers/exec/thread_for.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <stdexcept>
#include <thread>
#include <vector>

namespace eical::drivers {
namespace {

TEST(ThreadFor, RunsEveryTaskExactlyOnceBeforeReturning) {
  const dsp::ParallelFor parallel = thread_for(4);
  std::vector<int> slot(1000, 0);  // each task writes its own slot only
  std::atomic<int> calls{0};
  parallel(slot.size(), [&](std::size_t i) {
    slot[i] += static_cast<int>(i) + 1;
    ++calls;
  });
  EXPECT_EQ(calls.load(), 1000);
  for (std::size_t i = 0; i < slot.size(); ++i) ASSERT_EQ(slot[i], static_cast<int>(i) + 1) << i;
}

TEST(ThreadFor, UsesSeveralThreadsAndNoneForNoTask) {
  const dsp::ParallelFor parallel = thread_for(2);
  std::vector<std::thread::id> ran_on(2);
  std::atomic<int> arrived{0};
  parallel(2, [&](std::size_t i) {
    ran_on[i] = std::this_thread::get_id();
    ++arrived;
    while (arrived.load() < 2) std::this_thread::yield();  // both tasks at once: two threads
  });
  EXPECT_NE(ran_on[0], ran_on[1]);
  int calls = 0;
  parallel(0, [&](std::size_t) { ++calls; });
  EXPECT_EQ(calls, 0);
}

TEST(ThreadFor, RethrowsATasksExceptionAfterTheOthersFinished) {
  const dsp::ParallelFor parallel = thread_for(3);
  std::vector<int> done(64, 0);
  EXPECT_THROW(parallel(done.size(),
                        [&](std::size_t i) {
                          if (i == 7) throw std::runtime_error("task 7");
                          done[i] = 1;
                        }),
               std::runtime_error);
  for (std::size_t i = 0; i < done.size(); ++i) EXPECT_EQ(done[i], i == 7 ? 0 : 1) << i;
}

TEST(ThreadFor, OneThreadRunsTheTasksInOrderOnTheCaller) {
  std::vector<std::size_t> order;
  const auto caller = std::this_thread::get_id();
  bool on_caller = true;
  thread_for(1)(5, [&](std::size_t i) {
    order.push_back(i);
    on_caller = on_caller && std::this_thread::get_id() == caller;
  });
  EXPECT_EQ(order, (std::vector<std::size_t>{0, 1, 2, 3, 4}));
  EXPECT_TRUE(on_caller);
}

}  // namespace
}  // namespace eical::drivers
