#pragma once
// A first-in first-out queue of fixed capacity for one thread (frames a source holds back,
// servo samples waiting for their frames): storage allocated once in the constructor,
// push/pop/front never allocate, a full queue refuses the push (the caller counts it).
#include <cstddef>
#include <memory>
#include <stdexcept>
#include <type_traits>

namespace eical::drivers {

template <class T>
class FixedQueue {
  static_assert(std::is_trivially_copyable_v<T>, "queued items are plain data copied by value");

 public:
  explicit FixedQueue(std::size_t capacity) : capacity_(capacity) {
    if (capacity == 0) throw std::invalid_argument("FixedQueue capacity must be positive");
    slots_ = std::make_unique<T[]>(capacity);
  }

  [[nodiscard]] bool push(const T& item) noexcept {
    if (size_ == capacity_) return false;
    slots_[(head_ + size_) % capacity_] = item;
    ++size_;
    return true;
  }
  [[nodiscard]] T& front() noexcept { return slots_[head_]; }
  [[nodiscard]] const T& front() const noexcept { return slots_[head_]; }
  [[nodiscard]] const T& back() const noexcept { return slots_[(head_ + size_ - 1) % capacity_]; }
  // The k-th item from the front (k < size()).
  [[nodiscard]] const T& at(std::size_t k) const noexcept { return slots_[(head_ + k) % capacity_]; }
  void pop() noexcept {
    head_ = (head_ + 1) % capacity_;
    --size_;
  }
  void clear() noexcept { head_ = size_ = 0; }
  [[nodiscard]] bool empty() const noexcept { return size_ == 0; }
  [[nodiscard]] bool full() const noexcept { return size_ == capacity_; }
  [[nodiscard]] std::size_t size() const noexcept { return size_; }
  [[nodiscard]] std::size_t capacity() const noexcept { return capacity_; }

 private:
  std::size_t capacity_;
  std::unique_ptr<T[]> slots_;
  std::size_t head_ = 0, size_ = 0;
};

}  // namespace eical::drivers
