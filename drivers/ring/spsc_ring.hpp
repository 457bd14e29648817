#pragma once
// Lock-free single-producer single-consumer ring (after rigtorp/SPSCQueue): the
// acquisition thread pushes frames, the DSP thread pops them.
//  * fixed power-of-two capacity, storage allocated once in the constructor;
//  * the producer never blocks: push_or_drop() drops the NEWEST frame when full and
//    counts an overrun (the DAQ keeps sampling; older frames already queued stay intact);
//  * acquire/release on the indices only; each index and the other side's cached copy
//    of it sit on their own cache line, so producer and consumer do not false-share.
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <new>
#include <span>
#include <stdexcept>
#include <string>
#include <type_traits>

namespace eical::drivers {

// std::hardware_destructive_interference_size is 64 on x86-64 and arm64 but GCC warns
// that its value may change between compiler versions (ABI); fix it here.
inline constexpr std::size_t kCacheLine = 64;

template <class T>
class SpscRing {
  static_assert(std::is_trivially_copyable_v<T>, "ring payloads are plain data copied by value");

 public:
  explicit SpscRing(std::size_t capacity) : capacity_(capacity), mask_(capacity - 1) {
    if (capacity < 2 || (capacity & (capacity - 1)) != 0)
      throw std::invalid_argument("SpscRing capacity must be a power of two >= 2, got " + std::to_string(capacity));
    slots_ = std::make_unique<T[]>(capacity);
  }

  SpscRing(const SpscRing&) = delete;
  SpscRing& operator=(const SpscRing&) = delete;

  // Producer. False when full (nothing written).
  [[nodiscard]] bool try_push(const T& item) noexcept {
    const std::size_t w = write_.load(std::memory_order_relaxed);
    if (w - read_cached_ == capacity_) {
      read_cached_ = read_.load(std::memory_order_acquire);
      if (w - read_cached_ == capacity_) return false;
    }
    slots_[w & mask_] = item;
    write_.store(w + 1, std::memory_order_release);
    return true;
  }

  // Producer, live sources: never blocks; a full ring drops `item` and counts it.
  bool push_or_drop(const T& item) noexcept {
    if (try_push(item)) return true;
    overruns_.fetch_add(1, std::memory_order_relaxed);
    return false;
  }

  // Consumer. False when empty.
  [[nodiscard]] bool try_pop(T& out) noexcept {
    const std::size_t r = read_.load(std::memory_order_relaxed);
    if (r == write_cached_) {
      write_cached_ = write_.load(std::memory_order_acquire);
      if (r == write_cached_) return false;
    }
    out = slots_[r & mask_];
    read_.store(r + 1, std::memory_order_release);
    return true;
  }

  // Consumer: up to out.size() items with one acquire load and one release store.
  std::size_t pop_many(std::span<T> out) noexcept {
    const std::size_t r = read_.load(std::memory_order_relaxed);
    write_cached_ = write_.load(std::memory_order_acquire);
    std::size_t n = write_cached_ - r;
    if (n > out.size()) n = out.size();
    for (std::size_t k = 0; k < n; ++k) out[k] = slots_[(r + k) & mask_];
    if (n > 0) read_.store(r + n, std::memory_order_release);
    return n;
  }

  // Any thread; approximate while both sides run.
  [[nodiscard]] std::size_t size_approx() const noexcept {
    const std::size_t w = write_.load(std::memory_order_acquire);
    const std::size_t r = read_.load(std::memory_order_acquire);
    return w >= r ? w - r : 0;
  }
  [[nodiscard]] std::size_t capacity() const noexcept { return capacity_; }
  [[nodiscard]] std::uint64_t overruns() const noexcept { return overruns_.load(std::memory_order_relaxed); }

 private:
  const std::size_t capacity_;
  const std::size_t mask_;
  std::unique_ptr<T[]> slots_;
  // Indices count up without wrapping (2^64 items at 10 kHz: 58 million years).
  alignas(kCacheLine) std::atomic<std::size_t> write_{0};
  alignas(kCacheLine) std::size_t read_cached_ = 0;  // producer's copy of read_
  alignas(kCacheLine) std::atomic<std::size_t> read_{0};
  alignas(kCacheLine) std::size_t write_cached_ = 0;  // consumer's copy of write_
  alignas(kCacheLine) std::atomic<std::uint64_t> overruns_{0};
};

}  // namespace eical::drivers
