#pragma once
// Decoder of the USB DAQ stream (PROTOCOL.md): arbitrary byte chunks in, frames out.
// Pure logic — no libusb — so framing, CRC and re-synchronisation are tested on byte
// streams. Fixed-size buffer; feed() does not allocate.
#include "dsp/core/frame.hpp"

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <span>
#include <vector>

namespace eical::drivers::usb_daq {

inline constexpr std::uint8_t kSync0 = 0xEA, kSync1 = 0x1C, kVersion = 1;
inline constexpr std::uint8_t kTypeSamples = 1, kTypeSlow = 2;
inline constexpr std::size_t kHeader = 10, kCrc = 2;

std::uint16_t crc16_ccitt(std::span<const std::uint8_t> bytes, std::uint16_t crc = 0xFFFF);

struct DecoderStats {
  std::uint64_t packets = 0, frames = 0;
  std::uint64_t crc_errors = 0, resync_bytes = 0, unknown_packets = 0, lost_samples = 0;
};

class Decoder {
 public:
  // `psd_count`: PSD strips expected per sample (the channel count is checked against it).
  explicit Decoder(int psd_count);
  // Consumes bytes (a chunk of any size: UsbDaqSource reads 16 KiB transfers, twice the
  // buffer); calls `emit(frame)` for every sample decoded. The buffer is parsed whenever
  // it fills, so a chunk larger than the buffer loses nothing.
  template <class Emit>
  void feed(std::span<const std::uint8_t> bytes, Emit&& emit) {
    while (!bytes.empty()) {
      if (fill_ == buf_.size()) drop(1);  // parse leaves at most one partial packet: cannot happen; keeps us bounded
      const std::size_t n = std::min(bytes.size(), buf_.size() - fill_);
      std::copy_n(bytes.begin(), n, buf_.begin() + static_cast<std::ptrdiff_t>(fill_));
      fill_ += n;
      bytes = bytes.subspan(n);
      parse([&](const dsp::Frame& f) { emit(f); });
    }
  }
  [[nodiscard]] const DecoderStats& stats() const { return stats_; }
  [[nodiscard]] float temp_c(int sensor) const { return temp_c_[sensor]; }

 private:
  void parse(const std::function<void(const dsp::Frame&)>& emit);
  void drop(std::size_t n);
  int psd_count_;
  std::array<std::uint8_t, 8192> buf_{};
  std::size_t fill_ = 0;
  DecoderStats stats_;
  bool have_seq_ = false;
  std::uint32_t next_seq_ = 0;
  std::int64_t next_index_ = 0;  // unwrapped sample index expected next
  float temp_c_[2] = {0.0f, 0.0f};
  int pending_trigger_ = 0;
};

// The firmware side, for tests and the device simulator: one samples packet.
std::vector<std::uint8_t> encode_samples(std::uint32_t sequence, const std::vector<std::array<std::int32_t, 14>>& samples, int channels,
                                         std::uint8_t status = 0);
std::vector<std::uint8_t> encode_slow(std::uint32_t sequence, float temp_table_c, float temp_head_c, int trigger);

}  // namespace eical::drivers::usb_daq
