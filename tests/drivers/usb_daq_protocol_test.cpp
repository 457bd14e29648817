// The USB DAQ stream decoder on byte streams: framing across arbitrary chunks, 24-bit
// sign extension, CRC rejection, re-synchronisation after garbage, lost samples.
#include "drivers/usb_daq/protocol.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <iterator>
#include <random>

namespace eical::drivers::usb_daq {
namespace {

std::vector<SampleChannels> samples(int n, int base) {
  std::vector<SampleChannels> v(static_cast<std::size_t>(n));
  for (int k = 0; k < n; ++k)
    for (int c = 0; c < 10; ++c)
      v[static_cast<std::size_t>(k)][static_cast<std::size_t>(c)] = (base + k) * (c % 2 ? -1 : 1) * 1000 + c;
  v[0][5] = -(1 << 23);  // full negative scale survives the 24-bit packing
  v[0][4] = (1 << 23) - 1;
  return v;
}

TEST(UsbDaqProtocol, CrcMatchesTheStandardCheckValue) {
  const std::uint8_t check[] = {'1', '2', '3', '4', '5', '6', '7', '8', '9'};
  EXPECT_EQ(crc16_ccitt(check), 0x29B1);  // CRC-16/CCITT-FALSE of "123456789"
}

TEST(UsbDaqProtocol, FramesSurviveArbitraryChunking) {
  std::vector<std::uint8_t> stream;
  for (int p = 0; p < 20; ++p) {
    const auto pk = encode_samples(static_cast<std::uint32_t>(p * 8), samples(8, p * 8), 10);
    stream.insert(stream.end(), pk.begin(), pk.end());
    if (p == 3) {
      const auto slow = encode_slow(32, 21.55f, 22.3f, 101);
      stream.insert(stream.end(), slow.begin(), slow.end());
    }
  }
  Decoder d(2);
  std::vector<dsp::Frame> out;
  std::mt19937 rng(1);
  for (std::size_t at = 0; at < stream.size();) {
    const std::size_t n = std::min<std::size_t>(1 + rng() % 97, stream.size() - at);
    d.feed(std::span<const std::uint8_t>(stream.data() + at, n), [&](const dsp::Frame& f) { out.push_back(f); });
    at += n;
  }
  ASSERT_EQ(out.size(), 160u);
  for (std::size_t i = 0; i < out.size(); ++i) {
    ASSERT_EQ(out[i].sample_index, static_cast<std::int64_t>(i));
    ASSERT_EQ(out[i].flags & dsp::frame_flag::gap_before, 0u);
  }
  EXPECT_EQ(out[0].accel_counts[5], -(1 << 23));
  EXPECT_EQ(out[0].accel_counts[4], (1 << 23) - 1);
  EXPECT_EQ(out[9].accel_counts[1], -9 * 1000 + 1);  // channel 1: -(sample) * 1000 + 1
  EXPECT_EQ(out[9].psd_counts[3], -9 * 1000 + 9);    // channel 9
  EXPECT_EQ(out[32].trigger, 101);                   // the slow packet's trigger lands on the next sample
  EXPECT_FLOAT_EQ(out[40].temp_c[0], 21.55f);
  EXPECT_EQ(d.stats().crc_errors, 0u);
}

// Found by fuzz/usb_daq.cpp (issue 21): the decoder buffered a whole chunk before parsing,
// so of a 16 KiB bulk transfer (what UsbDaqSource reads) into its 8 KiB buffer the first
// half was dropped byte by byte — 320 of 640 frames recorded. A chunk of any size is
// parsed as it fills the buffer now.
TEST(UsbDaqProtocol, AFullBulkTransferLosesNothing) {
  std::vector<std::uint8_t> transfer;
  std::uint32_t seq = 0;
  while (transfer.size() < 16384 - 2000) {
    const auto pk = encode_samples(seq, samples(64, static_cast<int>(seq)), 8);
    transfer.insert(transfer.end(), pk.begin(), pk.end());
    seq += 64;
  }
  ASSERT_GT(transfer.size(), 8192u);  // more than the decoder's buffer
  Decoder d(1);
  std::vector<dsp::Frame> out;
  d.feed(transfer, [&](const dsp::Frame& f) { out.push_back(f); });
  ASSERT_EQ(out.size(), seq);
  for (std::size_t k = 0; k < out.size(); ++k) EXPECT_EQ(out[k].sample_index, static_cast<std::int64_t>(k));
  EXPECT_EQ(d.stats().resync_bytes, 0u);
  EXPECT_EQ(d.stats().lost_samples, 0u);
  EXPECT_EQ(d.stats().packets, seq / 64);
}

// The seed that showed it, through the decoder as the source feeds it (fuzz/corpus/usb_daq:
// byte 0 is the fuzz target's option byte).
TEST(UsbDaqProtocol, FuzzSeedFullTransferDecodesEveryFrame) {
  std::ifstream is(EICAL_SOURCE_DIR "/fuzz/corpus/usb_daq/full-transfer", std::ios::binary);
  ASSERT_TRUE(is);
  const std::vector<std::uint8_t> bytes((std::istreambuf_iterator<char>(is)), std::istreambuf_iterator<char>());
  ASSERT_GT(bytes.size(), 8193u);
  Decoder d(1);
  std::size_t frames = 0;
  d.feed(std::span<const std::uint8_t>(bytes).subspan(1), [&](const dsp::Frame&) { ++frames; });
  EXPECT_EQ(frames, 640u);
  EXPECT_EQ(d.stats().crc_errors, 0u);
}

// 16 strips: 6 + 32 channels a sample, each electrode where the frame keeps it.
TEST(UsbDaqProtocol, SixteenStripsDecodeEveryElectrode) {
  constexpr int kChannels = kMaxChannels;
  std::vector<SampleChannels> v(8);
  for (std::size_t k = 0; k < v.size(); ++k)
    for (int c = 0; c < kChannels; ++c) v[k][static_cast<std::size_t>(c)] = 1000 * c - static_cast<int>(k);
  const auto pk = encode_samples(0, v, kChannels);
  Decoder d(dsp::kMaxPsd);
  std::vector<dsp::Frame> out;
  d.feed(pk, [&](const dsp::Frame& f) { out.push_back(f); });
  ASSERT_EQ(out.size(), v.size());
  EXPECT_EQ(out[3].psd_counts[0], 1000 * dsp::kAccelChannels - 3);
  EXPECT_EQ(out[3].psd_counts[31], 1000 * (kChannels - 1) - 3);
  EXPECT_EQ(d.stats().crc_errors, 0u);
}

TEST(UsbDaqProtocol, CorruptPacketIsDroppedAndTheStreamResynchronises) {
  std::vector<std::uint8_t> stream = {0x00, 0xEA, 0x13, 0xEA, 0x1C, 0x07};  // garbage, including a false sync
  auto a = encode_samples(0, samples(4, 0), 10);
  auto b = encode_samples(4, samples(4, 4), 10);
  auto c = encode_samples(8, samples(4, 8), 10);
  b[20] ^= 0x40;  // one bit flipped inside packet b
  for (auto* p : {&a, &b, &c}) stream.insert(stream.end(), p->begin(), p->end());
  Decoder d(2);
  std::vector<dsp::Frame> out;
  d.feed(stream, [&](const dsp::Frame& f) { out.push_back(f); });
  ASSERT_EQ(out.size(), 8u);  // a and c
  EXPECT_GE(d.stats().crc_errors + d.stats().unknown_packets, 1u);
  EXPECT_EQ(d.stats().lost_samples, 4u);
  EXPECT_EQ(out[4].sample_index, 8);
  EXPECT_NE(out[4].flags & dsp::frame_flag::gap_before, 0u);  // nothing recorded is hidden
}

TEST(UsbDaqProtocol, SequenceWrapsWithoutAGap) {
  Decoder d(0);
  std::vector<dsp::Frame> out;
  const auto a = encode_samples(0xFFFFFFFCu, samples(4, 0), 6);
  const auto b = encode_samples(0, samples(4, 4), 6);
  d.feed(a, [&](const dsp::Frame& f) { out.push_back(f); });
  d.feed(b, [&](const dsp::Frame& f) { out.push_back(f); });
  ASSERT_EQ(out.size(), 8u);
  EXPECT_EQ(out[7].sample_index - out[0].sample_index, 7);
  EXPECT_EQ(d.stats().lost_samples, 0u);
}

}  // namespace
}  // namespace eical::drivers::usb_daq
