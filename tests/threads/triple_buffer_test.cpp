// The triple buffer between the status thread and the HMI publisher: the reader always
// sees a whole value (never one torn between two writes), the newest once it updates, and
// neither side waits. Runs under ThreadSanitizer in scripts/test (label threads).
#include "drivers/ring/triple_buffer.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <string>
#include <thread>

namespace eical::drivers {
namespace {

struct Value {
  std::uint64_t n = 0;
  std::string text;  // owns memory, as the Status message's strings do
  std::uint64_t check = 0;
};

TEST(TripleBuffer, TheReaderSeesWholeValuesInOrderAndTheLast) {
  TripleBuffer<Value> tb;
  constexpr std::uint64_t kValues = 200000;
  std::atomic<bool> done{false};
  std::thread writer([&] {
    for (std::uint64_t n = 1; n <= kValues; ++n) {
      Value& v = tb.back();
      v.n = n;
      v.text = "value " + std::to_string(n);
      v.check = n * 7 + 3;
      tb.publish();
    }
    done = true;
  });
  std::uint64_t last = 0, seen = 0;
  bool finished = false;
  while (!finished) {
    finished = done.load();  // after the writer's last publish, one more update shows it
    if (!tb.update()) continue;
    const Value& v = tb.front();
    ASSERT_EQ(v.check, v.n * 7 + 3) << "torn value";
    ASSERT_EQ(v.text, "value " + std::to_string(v.n));
    ASSERT_GT(v.n, last) << "went back";
    last = v.n;
    ++seen;
  }
  writer.join();
  (void)tb.update();
  EXPECT_EQ(tb.front().n, kValues) << "the newest value arrives";
  EXPECT_GT(seen, 0u);
}

}  // namespace
}  // namespace eical::drivers
