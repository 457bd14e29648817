#include "drivers/usb_daq/frame_encoder.hpp"

#include "drivers/usb_daq/protocol.hpp"

#include <algorithm>
#include <stdexcept>

namespace eical::drivers::usb_daq {
namespace {

void put_u32(std::vector<std::uint8_t>& p, std::uint32_t v) {
  for (int b = 0; b < 4; ++b) p.push_back(static_cast<std::uint8_t>(v >> (8 * b)));
}

void put_s24(std::vector<std::uint8_t>& p, std::int32_t v) {
  for (int b = 0; b < 3; ++b) p.push_back(static_cast<std::uint8_t>(static_cast<std::uint32_t>(v) >> (8 * b)));
}

void put_crc(std::vector<std::uint8_t>& p, std::size_t packet_start) {
  const std::uint16_t crc = crc16_ccitt(std::span<const std::uint8_t>(p).subspan(packet_start + 2));
  p.push_back(static_cast<std::uint8_t>(crc & 0xFF));
  p.push_back(static_cast<std::uint8_t>(crc >> 8));
}

}  // namespace

FrameEncoder::FrameEncoder(int psd_count, int samples_per_packet, int slow_every)
    : channels_(dsp::kAccelChannels + 2 * psd_count), per_packet_(samples_per_packet), slow_every_(slow_every) {
  if (psd_count < 0 || psd_count > dsp::kMaxPsd)
    throw std::invalid_argument("FrameEncoder: psd_count must be within 0..4");
  if (samples_per_packet < 1 || samples_per_packet > kMaxSamplesPerPacket)
    throw std::invalid_argument("FrameEncoder: 1..64 samples per packet");
}

void FrameEncoder::samples_packet(std::span<const dsp::Frame> frames, std::vector<std::uint8_t>& out) const {
  const std::size_t start = out.size();
  out.insert(out.end(), {kSync0, kSync1, kVersion, kTypeSamples, static_cast<std::uint8_t>(channels_),
                         static_cast<std::uint8_t>(frames.size())});
  put_u32(out, static_cast<std::uint32_t>(frames.front().sample_index));
  for (const auto& f : frames) {
    std::uint8_t status = 0;
    if (f.flags & dsp::frame_flag::accel_saturated) status |= kStatusAccelOverload;
    out.push_back(status);
    for (int c = 0; c < dsp::kAccelChannels; ++c) put_s24(out, f.accel_counts[c]);
    for (int c = 0; c < channels_ - dsp::kAccelChannels; ++c) put_s24(out, f.psd_counts[c]);
  }
  put_crc(out, start);
}

void FrameEncoder::encode(std::span<const dsp::Frame> frames, std::vector<std::uint8_t>& out) {
  std::size_t i = 0;
  while (i < frames.size()) {
    // One packet: up to per_packet_ consecutive samples, cut before the next trigger or jump.
    std::size_t n = 1;
    while (i + n < frames.size() && n < static_cast<std::size_t>(per_packet_) && frames[i + n].trigger == 0 &&
           frames[i + n].sample_index == frames[i + n - 1].sample_index + 1)
      ++n;
    const dsp::Frame& first = frames[i];
    if (first.trigger != 0 || packets_since_slow_ == 0) {
      const auto slow = encode_slow(static_cast<std::uint32_t>(first.sample_index), first.temp_c[0], first.temp_c[1],
                                    std::clamp(first.trigger, 0, 255));
      out.insert(out.end(), slow.begin(), slow.end());
    }
    packets_since_slow_ = (packets_since_slow_ + 1) % slow_every_;
    samples_packet(frames.subspan(i, n), out);
    i += n;
  }
}

}  // namespace eical::drivers::usb_daq
