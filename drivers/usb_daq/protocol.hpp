#pragma once
// Decoder of the USB DAQ stream (PROTOCOL.md): arbitrary byte chunks in, frames out.
// Pure logic — no libusb — so framing, CRC and re-synchronisation are tested on byte
// streams, and the same decoder serves the USB bulk endpoint and a byte stream (a FIFO or
// socket, DaqStreamSource). Fixed-size buffer; feed() does not allocate, lock or throw.
#include "dsp/core/frame.hpp"

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <vector>

namespace eical::drivers::usb_daq {

inline constexpr std::uint8_t kSync0 = 0xEA, kSync1 = 0x1C, kVersion = 1;
inline constexpr std::uint8_t kTypeSamples = 1, kTypeSlow = 2;
inline constexpr std::size_t kHeader = 10, kCrc = 2;
inline constexpr int kMaxSamplesPerPacket = 64;
inline constexpr int kMaxChannels = dsp::kAccelChannels + 2 * dsp::kMaxPsd;
using SampleChannels = std::array<std::int32_t, kMaxChannels>;  // one sample's counts, accel then PSD
inline constexpr std::size_t kSlowPayload = 5;
inline constexpr std::uint8_t kStatusAccelOverload = 1u << 0, kStatusPsdOverload = 1u << 1;

std::uint16_t crc16_ccitt(std::span<const std::uint8_t> bytes, std::uint16_t crc = 0xFFFF);

struct DecoderStats {
  std::uint64_t packets = 0, frames = 0;
  std::uint64_t crc_errors = 0, resync_bytes = 0, unknown_packets = 0, lost_samples = 0;
};

class Decoder {
 public:
  // `psd_count`: PSD strips expected per sample (the channel count is checked against it).
  explicit Decoder(int psd_count) : psd_count_(psd_count) {}
  // Consumes bytes; calls `emit(frame)` for every sample decoded. Frames carry no NC
  // set-point (flag cmd_missing, cmd 0): it comes from another source.
  template <class Emit>
  void feed(std::span<const std::uint8_t> bytes, Emit&& emit) {
    while (!bytes.empty()) {
      const std::size_t n = std::min(bytes.size(), buf_.size() - fill_);
      std::memcpy(buf_.data() + fill_, bytes.data(), n);
      fill_ += n;
      bytes = bytes.subspan(n);
      parse(emit);
      // A full buffer without a complete packet is not the protocol: skip one byte.
      if (fill_ == buf_.size()) ++stats_.resync_bytes, drop(1);
    }
  }
  [[nodiscard]] const DecoderStats& stats() const { return stats_; }
  [[nodiscard]] float temp_c(int sensor) const { return temp_c_[sensor]; }
  // Back to the state of a new stream (the device was reopened).
  void reset() noexcept;

 private:
  enum class Step { need_more, consumed };
  template <class Emit>
  void parse(Emit& emit) {
    dsp::Frame block[kMaxSamplesPerPacket];
    for (;;) {
      int n = 0;
      if (parse_one(block, n) == Step::need_more) return;
      for (int k = 0; k < n; ++k) emit(static_cast<const dsp::Frame&>(block[k]));
    }
  }
  // Decodes the next packet in the buffer into `out` (n frames for a samples packet).
  Step parse_one(dsp::Frame* out, int& n) noexcept;
  std::size_t next_packet() noexcept;
  void read_slow(const std::uint8_t* payload, std::uint32_t seq) noexcept;
  int read_samples(const std::uint8_t* payload, std::uint32_t seq, int channels, int samples, dsp::Frame* out) noexcept;
  void drop(std::size_t n) noexcept;

  int psd_count_;
  std::array<std::uint8_t, 16384> buf_{};
  std::size_t fill_ = 0;
  DecoderStats stats_;
  bool have_seq_ = false;
  std::uint32_t next_seq_ = 0;
  std::int64_t next_index_ = 0;  // unwrapped sample index expected next
  float temp_c_[2] = {0.0f, 0.0f};
  int pending_trigger_ = 0;
  std::int64_t pending_trigger_index_ = 0;  // the sample the trigger was latched at
};

// The firmware side, for tests and the device simulator: one samples packet.
std::vector<std::uint8_t> encode_samples(std::uint32_t sequence, const std::vector<SampleChannels>& samples,
                                         int channels, std::uint8_t status = 0);
std::vector<std::uint8_t> encode_slow(std::uint32_t sequence, float temp_table_c, float temp_head_c, int trigger);

}  // namespace eical::drivers::usb_daq
