#include "drivers/usb_daq/protocol.hpp"

#include <cmath>
#include <cstring>

namespace eical::drivers::usb_daq {
namespace {

std::uint32_t u32(const std::uint8_t* p) {
  return static_cast<std::uint32_t>(p[0]) | static_cast<std::uint32_t>(p[1]) << 8 |
         static_cast<std::uint32_t>(p[2]) << 16 | static_cast<std::uint32_t>(p[3]) << 24;
}

std::int32_t s24(const std::uint8_t* p) {
  const std::uint32_t v =
      static_cast<std::uint32_t>(p[0]) | static_cast<std::uint32_t>(p[1]) << 8 | static_cast<std::uint32_t>(p[2]) << 16;
  return static_cast<std::int32_t>(v << 8) >> 8;  // sign-extend 24 → 32 bits
}

std::array<std::uint16_t, 256> crc_table() {
  std::array<std::uint16_t, 256> t{};
  for (unsigned i = 0; i < 256; ++i) {
    std::uint16_t c = static_cast<std::uint16_t>(i << 8);
    for (int k = 0; k < 8; ++k) c = static_cast<std::uint16_t>((c & 0x8000) ? (c << 1) ^ 0x1021 : c << 1);
    t[i] = c;
  }
  return t;
}

void put_crc(std::vector<std::uint8_t>& p) {
  const std::uint16_t crc = crc16_ccitt(std::span<const std::uint8_t>(p).subspan(2));
  p.push_back(static_cast<std::uint8_t>(crc & 0xFF));
  p.push_back(static_cast<std::uint8_t>(crc >> 8));
}

}  // namespace

std::uint16_t crc16_ccitt(std::span<const std::uint8_t> bytes, std::uint16_t crc) {
  static const auto table = crc_table();
  for (std::uint8_t b : bytes) crc = static_cast<std::uint16_t>((crc << 8) ^ table[((crc >> 8) ^ b) & 0xFF]);
  return crc;
}

void Decoder::reset() noexcept {
  fill_ = 0;
  have_seq_ = false;
  next_seq_ = 0;
  next_index_ = 0;
  pending_trigger_ = 0;
}

void Decoder::drop(std::size_t n) noexcept {
  std::memmove(buf_.data(), buf_.data() + n, fill_ - n);
  fill_ -= n;
}

// One packet from the buffer: its frames into `out` (n of them; none for a slow packet).
Decoder::Step Decoder::parse_one(dsp::Frame* out, int& n) noexcept {
  const std::size_t total = next_packet();
  if (total == 0) return Step::need_more;
  ++stats_.packets;
  const std::uint8_t type = buf_[3], channels = buf_[4], samples = buf_[5];
  const std::uint32_t seq = u32(&buf_[6]);
  n = 0;
  if (type == kTypeSlow)
    read_slow(&buf_[kHeader], seq);
  else
    n = read_samples(&buf_[kHeader], seq, channels, samples, out);
  drop(total);
  return Step::consumed;
}

// The size of the whole, checked packet at the buffer's start (0: more bytes are needed).
// What precedes a sync word, a header not understood and a packet whose CRC fails are
// dropped and counted.
std::size_t Decoder::next_packet() noexcept {
  for (;;) {
    std::size_t i = 0;
    while (i + 1 < fill_ && !(buf_[i] == kSync0 && buf_[i + 1] == kSync1)) ++i;
    if (i > 0) {
      stats_.resync_bytes += i;
      drop(i);
    }
    if (fill_ < kHeader) return 0;
    const std::uint8_t version = buf_[2], type = buf_[3], channels = buf_[4], samples = buf_[5];
    const std::size_t payload = type == kTypeSamples
                                    ? static_cast<std::size_t>(samples) * (1 + 3 * static_cast<std::size_t>(channels))
                                : type == kTypeSlow ? kSlowPayload
                                                    : 0;
    if (version != kVersion || payload == 0 || samples > kMaxSamplesPerPacket || channels > kMaxChannels) {
      ++stats_.unknown_packets;
      drop(2);  // not a packet we understand: look for the next sync
      continue;
    }
    const std::size_t total = kHeader + payload + kCrc;
    if (fill_ < total) return 0;
    const std::uint16_t crc = static_cast<std::uint16_t>(buf_[total - 2] | buf_[total - 1] << 8);
    if (crc16_ccitt(std::span<const std::uint8_t>(buf_.data() + 2, total - 4)) == crc) return total;
    ++stats_.crc_errors;
    drop(2);  // the sync was data or the packet is damaged: search on
  }
}

// The slow channels: both temperatures, and a trigger latched at `seq`.
void Decoder::read_slow(const std::uint8_t* payload, std::uint32_t seq) noexcept {
  temp_c_[0] = static_cast<float>(static_cast<std::int16_t>(payload[0] | payload[1] << 8)) / 100.0f;
  temp_c_[1] = static_cast<float>(static_cast<std::int16_t>(payload[2] | payload[3] << 8)) / 100.0f;
  if (payload[4] != 0) {
    // Latched at `seq`: unwrapped against the samples seen so far.
    pending_trigger_ = payload[4];
    pending_trigger_index_ =
        have_seq_ ? next_index_ + static_cast<std::int32_t>(seq - next_seq_) : static_cast<std::int64_t>(seq);
  }
}

// A samples packet as frames; a jump of its sequence number is counted and flagged.
int Decoder::read_samples(const std::uint8_t* payload, std::uint32_t seq, int channels, int samples,
                          dsp::Frame* out) noexcept {
  // Sequence numbers wrap at 2^32; the sample index is unwrapped from the last one.
  bool gap = false;
  std::int64_t first;
  if (!have_seq_) {
    first = seq;
    have_seq_ = true;
  } else {
    const std::uint32_t missing = seq - next_seq_;  // mod 2^32: a forward jump
    gap = missing != 0;
    stats_.lost_samples += missing;
    first = next_index_ + missing;
  }
  const int n_psd_ch = channels - dsp::kAccelChannels;
  for (int k = 0; k < samples; ++k) {
    dsp::Frame& f = out[k];
    f = dsp::Frame{};
    const std::uint8_t status = *payload++;
    f.sample_index = first + k;
    for (int c = 0; c < dsp::kAccelChannels && c < channels; ++c, payload += 3) f.accel_counts[c] = s24(payload);
    for (int c = 0; c < n_psd_ch; ++c, payload += 3) f.psd_counts[c] = s24(payload);
    if (channels < dsp::kAccelChannels) f.flags |= dsp::frame_flag::accel_missing;
    if (n_psd_ch < 2 * psd_count_) f.flags |= dsp::frame_flag::psd_missing;
    if (status & kStatusAccelOverload) f.flags |= dsp::frame_flag::accel_saturated;
    if (k == 0 && gap) f.flags |= dsp::frame_flag::gap_before;
    f.temp_c[0] = temp_c_[0], f.temp_c[1] = temp_c_[1];
    f.flags |= dsp::frame_flag::cmd_missing;  // the NC set-point comes from another source
    if (pending_trigger_ && f.sample_index >= pending_trigger_index_)
      f.trigger = pending_trigger_, pending_trigger_ = 0;
    ++stats_.frames;
  }
  next_seq_ = seq + static_cast<std::uint32_t>(samples);
  next_index_ = first + samples;
  return samples;
}

std::vector<std::uint8_t> encode_samples(std::uint32_t sequence, const std::vector<SampleChannels>& samples,
                                         int channels, std::uint8_t status) {
  channels = std::clamp(channels, 0, kMaxChannels);
  std::vector<std::uint8_t> p = {kSync0,
                                 kSync1,
                                 kVersion,
                                 kTypeSamples,
                                 static_cast<std::uint8_t>(channels),
                                 static_cast<std::uint8_t>(samples.size())};
  for (int b = 0; b < 4; ++b) p.push_back(static_cast<std::uint8_t>(sequence >> (8 * b)));
  for (const auto& s : samples) {
    p.push_back(status);
    for (int c = 0; c < channels; ++c)
      for (int b = 0; b < 3; ++b)
        p.push_back(static_cast<std::uint8_t>(static_cast<std::uint32_t>(s[static_cast<std::size_t>(c)]) >> (8 * b)));
  }
  put_crc(p);
  return p;
}

std::vector<std::uint8_t> encode_slow(std::uint32_t sequence, float temp_table_c, float temp_head_c, int trigger) {
  std::vector<std::uint8_t> p = {kSync0, kSync1, kVersion, kTypeSlow, 0, 1};
  for (int b = 0; b < 4; ++b) p.push_back(static_cast<std::uint8_t>(sequence >> (8 * b)));
  for (float t : {temp_table_c, temp_head_c}) {
    const auto v = static_cast<std::int16_t>(std::lround(t * 100.0f));
    p.push_back(static_cast<std::uint8_t>(v & 0xFF));
    p.push_back(static_cast<std::uint8_t>((static_cast<std::uint16_t>(v) >> 8) & 0xFF));
  }
  p.push_back(static_cast<std::uint8_t>(trigger));
  put_crc(p);
  return p;
}

}  // namespace eical::drivers::usb_daq
