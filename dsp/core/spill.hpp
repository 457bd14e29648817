#pragma once
// Records written once and read back in order, as often as needed: where an evaluation
// that must see its samples more than once (the circle diagnostics' least squares, the
// spread of averaged repeats) keeps them when the measurement is too long to hold. The
// interface is all dsp/ knows; MemorySpill keeps them here, drivers/ writes them to a file
// (no I/O in dsp/).
#include <cstddef>
#include <cstring>
#include <functional>
#include <memory>
#include <stdexcept>
#include <type_traits>
#include <vector>

namespace eical::dsp {

class Spill {
 public:
  virtual ~Spill() = default;
  // Appends bytes (whole records; the caller's record size).
  virtual void write(const void* data, std::size_t bytes) = 0;
  // Everything written, from the start, in blocks that are whole multiples of record_bytes.
  virtual void read(std::size_t record_bytes,
                    const std::function<void(const void* data, std::size_t bytes)>& block) = 0;
  // `bytes` from `offset` (within what was written) into out.
  virtual void read_at(std::size_t offset, void* out, std::size_t bytes) = 0;
  [[nodiscard]] virtual std::size_t bytes() const = 0;
};

// Makes the spills an evaluation needs (one per kind of record).
using SpillFactory = std::function<std::unique_ptr<Spill>()>;

class MemorySpill final : public Spill {
 public:
  void write(const void* data, std::size_t bytes) override {
    const auto* p = static_cast<const unsigned char*>(data);
    bytes_.insert(bytes_.end(), p, p + bytes);
  }
  void read(std::size_t, const std::function<void(const void*, std::size_t)>& block) override {
    if (!bytes_.empty()) block(bytes_.data(), bytes_.size());
  }
  void read_at(std::size_t offset, void* out, std::size_t bytes) override {
    if (offset + bytes > bytes_.size()) throw std::out_of_range("spill: read beyond what was written");
    std::memcpy(out, bytes_.data() + offset, bytes);
  }
  [[nodiscard]] std::size_t bytes() const override { return bytes_.size(); }

 private:
  std::vector<unsigned char> bytes_;
};

inline SpillFactory memory_spills() {
  return [] { return std::make_unique<MemorySpill>(); };
}

// A record of N doubles (Eigen's vectors are not trivially copyable).
template <int N>
struct Doubles {
  double v[N];
};

// Typed records through a spill, buffered (a few thousand at a time).
template <class T>
class SpillWriter {
  static_assert(std::is_trivially_copyable_v<T>);

 public:
  explicit SpillWriter(Spill& spill) : spill_(spill) { buf_.reserve(kBlock); }
  ~SpillWriter() { flush(); }
  SpillWriter(const SpillWriter&) = delete;
  SpillWriter& operator=(const SpillWriter&) = delete;
  void put(const T& r) {
    buf_.push_back(r);
    if (buf_.size() == kBlock) flush();
  }
  void flush() {
    if (!buf_.empty()) spill_.write(buf_.data(), buf_.size() * sizeof(T));
    buf_.clear();
  }

 private:
  static constexpr std::size_t kBlock = 4096;
  Spill& spill_;
  std::vector<T> buf_;
};

template <class T, class F>
void for_each_record(Spill& spill, F&& f) {
  static_assert(std::is_trivially_copyable_v<T>);
  spill.read(sizeof(T), [&](const void* data, std::size_t bytes) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (std::size_t off = 0; off + sizeof(T) <= bytes; off += sizeof(T)) {
      T r;
      std::memcpy(&r, p + off, sizeof(T));
      f(r);
    }
  });
}

}  // namespace eical::dsp
