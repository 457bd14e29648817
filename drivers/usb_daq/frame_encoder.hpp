#pragma once
// The DAQ firmware's side of the wire protocol (PROTOCOL.md): frames → packets. For the
// device simulator of the hardware-in-the-loop tests (simulated frames into the real
// decode path) and for bridging a DAQ that speaks another protocol. A packet never spans
// a trigger: the samples packet that holds a triggered sample starts with it, preceded by
// a slow packet latching the code at that sample.
#include "dsp/core/frame.hpp"

#include <cstdint>
#include <span>
#include <vector>

namespace eical::drivers::usb_daq {

class FrameEncoder {
 public:
  // psd_count: PSD strips per sample (channels = 6 + 2·psd_count); samples per packet 1…64;
  // a slow packet (temperatures) every `slow_every` samples packets.
  explicit FrameEncoder(int psd_count, int samples_per_packet = 32, int slow_every = 16);

  // Appends the packets of `frames` (consecutive sample indices; a jump is sent as such and
  // the decoder counts it as lost samples) to `out`.
  void encode(std::span<const dsp::Frame> frames, std::vector<std::uint8_t>& out);

 private:
  void samples_packet(std::span<const dsp::Frame> frames, std::vector<std::uint8_t>& out) const;
  int channels_;
  int per_packet_;
  int slow_every_;
  int packets_since_slow_ = 0;
};

}  // namespace eical::drivers::usb_daq
