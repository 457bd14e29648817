#pragma once
// Bytes of the DAQ wire protocol in, frames out, for the sources that read it (USB bulk
// endpoint, byte stream): the decoder plus a fixed queue of decoded frames waiting to be
// read. No allocation after construction; a queue overflow (the reader took fewer frames
// than it fed bytes for: a programming error, not a run-time condition) is counted.
#include "drivers/ring/fixed_queue.hpp"
#include "drivers/usb_daq/protocol.hpp"

#include <cstdint>
#include <span>

namespace eical::drivers::usb_daq {

class DecodedFrames {
 public:
  explicit DecodedFrames(int psd_count, std::size_t capacity = 8192) : decoder_(psd_count), queue_(capacity) {}

  void feed(std::span<const std::uint8_t> bytes) noexcept {
    decoder_.feed(bytes, [this](const dsp::Frame& f) {
      if (!queue_.push(f)) ++dropped_;
    });
  }
  std::size_t pop(std::span<dsp::Frame> out) noexcept {
    std::size_t n = 0;
    while (n < out.size() && !queue_.empty()) out[n++] = queue_.front(), queue_.pop();
    return n;
  }
  [[nodiscard]] std::size_t size() const noexcept { return queue_.size(); }
  [[nodiscard]] const DecoderStats& stats() const noexcept { return decoder_.stats(); }
  [[nodiscard]] std::uint64_t dropped() const noexcept { return dropped_; }
  void reset() noexcept {
    decoder_.reset();
    queue_.clear();
  }

 private:
  Decoder decoder_;
  FixedQueue<dsp::Frame> queue_;
  std::uint64_t dropped_ = 0;
};

}  // namespace eical::drivers::usb_daq
