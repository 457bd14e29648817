// Fuzz target: the USB DAQ wire protocol (drivers/usb_daq/PROTOCOL.md) through
// usb_daq::Decoder. Byte 0 chooses the PSD strips expected (0..16) and the chunking; the
// rest is the byte stream. Differential check: the stream fed as the source reads it
// (bulk transfers of up to 16 KiB) and fed in small uneven chunks must decode to the same
// frames and statistics — how the bytes are split into transfers must not change what is
// recorded. Also: sample indices increase, every frame carries cmd_missing.
#include "drivers/usb_daq/protocol.hpp"
#include "fuzz/fuzz_support.hpp"

#include <cstring>
#include <vector>

namespace {

using namespace eical;

constexpr std::size_t kTransferBytes = 16384;  // UsbDaqSource's bulk transfer buffer

struct Decoded {
  std::vector<dsp::Frame> frames;
  drivers::usb_daq::DecoderStats stats;
};

template <class NextChunk>
Decoded decode(int psd_count, std::span<const std::uint8_t> bytes, NextChunk&& next_chunk) {
  drivers::usb_daq::Decoder d(psd_count);
  Decoded out;
  for (std::size_t at = 0; at < bytes.size();) {
    const std::size_t n = std::min(next_chunk(), bytes.size() - at);
    d.feed(bytes.subspan(at, n), [&](const dsp::Frame& f) { out.frames.push_back(f); });
    at += n;
  }
  out.stats = d.stats();
  return out;
}

// Field by field, each field's bytes (cmd_mm and ref_mm may be NaN in both): the frame's
// padding is no part of what is recorded, and nothing guarantees it the same.
template <class T>
bool same_bytes(const T& a, const T& b) {
  return std::memcmp(&a, &b, sizeof a) == 0;
}

bool same(const dsp::Frame& a, const dsp::Frame& b) {
  return same_bytes(a.sample_index, b.sample_index) && same_bytes(a.accel_counts, b.accel_counts) &&
         same_bytes(a.psd_counts, b.psd_counts) && same_bytes(a.temp_c, b.temp_c) && same_bytes(a.cmd_mm, b.cmd_mm) &&
         same_bytes(a.ref_mm, b.ref_mm) && a.trigger == b.trigger && a.flags == b.flags &&
         a.psd_missing_electrodes == b.psd_missing_electrodes;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  const int psd_count = data[0] % (dsp::kMaxPsd + 1);
  const std::uint8_t chunk_seed = data[0] / (dsp::kMaxPsd + 1);
  const std::span<const std::uint8_t> bytes(data + 1, size - 1);
  const Decoded whole = decode(psd_count, bytes, [] { return kTransferBytes; });
  std::size_t k = 0;
  const Decoded pieces = decode(psd_count, bytes, [&] { return 1 + (chunk_seed + 7 * k++) % 61; });
  if (whole.frames.size() != pieces.frames.size())
    fuzz::finding("16 KiB transfers gave " + std::to_string(whole.frames.size()) + " frames, small chunks " +
                  std::to_string(pieces.frames.size()));
  for (std::size_t i = 0; i < whole.frames.size(); ++i) {
    if (!same(whole.frames[i], pieces.frames[i]))
      fuzz::finding("frame " + std::to_string(i) + " differs between chunkings");
    if (i > 0 && whole.frames[i].sample_index <= whole.frames[i - 1].sample_index)
      fuzz::finding("sample index does not increase");
    if (!(whole.frames[i].flags & dsp::frame_flag::cmd_missing)) fuzz::finding("a DAQ frame without cmd_missing");
  }
  const auto& a = whole.stats;
  const auto& b = pieces.stats;
  if (a.packets != b.packets || a.crc_errors != b.crc_errors || a.resync_bytes != b.resync_bytes ||
      a.unknown_packets != b.unknown_packets || a.lost_samples != b.lost_samples)
    fuzz::finding("decoder statistics differ between chunkings");
  return 0;
}
