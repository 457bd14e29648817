#pragma once
// The latest value from one writer thread to one reader thread without a lock (a triple
// buffer): the writer fills its back buffer and swaps it into the middle; the reader swaps
// the middle into its front when a new value is there. Neither ever waits for the other,
// so a real-time reader cannot be held up by a preempted writer (no priority inversion).
// T may own memory (strings): the writer's assignment allocates on the writer's thread;
// the reader only swaps indices.
#include <atomic>
#include <cstdint>

namespace eical::drivers {

template <class T>
class TripleBuffer {
 public:
  // Writer thread.
  T& back() noexcept { return slots_[back_]; }
  void publish() noexcept {
    const std::uint8_t old = middle_.exchange(static_cast<std::uint8_t>(back_ | kFresh), std::memory_order_acq_rel);
    back_ = old & kIndex;
  }
  // Reader thread: true when a value newer than the last read is now in front().
  bool update() noexcept {
    if ((middle_.load(std::memory_order_relaxed) & kFresh) == 0) return false;
    const std::uint8_t old = middle_.exchange(front_, std::memory_order_acq_rel);
    front_ = old & kIndex;
    return true;
  }
  [[nodiscard]] T& front() noexcept { return slots_[front_]; }

  // Before the threads start: every buffer holds `v`.
  void fill(const T& v) {
    for (auto& s : slots_) s = v;
  }

 private:
  static constexpr std::uint8_t kIndex = 0x3, kFresh = 0x4;
  T slots_[3]{};
  std::uint8_t back_ = 0;                // writer's
  std::atomic<std::uint8_t> middle_{1};  // index | kFresh when the writer published since the last swap
  std::uint8_t front_ = 2;               // reader's
};

}  // namespace eical::drivers
