// The Command payload as it arrives from the wire (drivers/dds/command_cdr): what a writer
// sends decodes to the same command in every plain encoding; malformed bytes are refused
// with a reason, never read past (the fuzz target fuzz/dds_command.cpp drives the rest).
#include "drivers/dds/command_cdr.hpp"
#include "dsp/core/float_limits.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>

namespace eical::drivers::dds {
namespace {

CommandMsg sample() {
  CommandMsg m;
  m.sender = "eical-trigger-42";
  m.request_id = 7;
  m.action = "trigger";
  m.code = 102;
  m.p = 2.5;
  m.q = kNaN;
  m.time_ns = 123456789012;
  return m;
}

TEST(DdsCommandCdr, WhatAWriterSendsDecodesToTheSameCommand) {
  const CommandMsg m = sample();
  const auto bytes = encode_command(m);
  ASSERT_GE(bytes.size(), 4u);
  EXPECT_EQ(bytes[0], 0x00);
  EXPECT_EQ(bytes[1], 0x01);  // CDR_LE
  std::string why;
  const auto back = decode_command(bytes, &why);
  ASSERT_TRUE(back) << why;
  EXPECT_EQ(back->sender, m.sender);
  EXPECT_EQ(back->request_id, m.request_id);
  EXPECT_EQ(back->action, m.action);
  EXPECT_EQ(back->code, m.code);
  EXPECT_EQ(back->p, m.p);
  EXPECT_TRUE(std::isnan(back->q));
  EXPECT_EQ(back->time_ns, m.time_ns);
}

// The same command big-endian: the body byte-swapped field by field (strings keep their
// bytes, lengths and numbers swap).
TEST(DdsCommandCdr, BigEndianPayloadDecodesLikeLittleEndian) {
  const CommandMsg m = sample();
  auto bytes = encode_command(m);
  auto swap = [&](std::size_t at, std::size_t n) {
    std::reverse(bytes.begin() + static_cast<std::ptrdiff_t>(at), bytes.begin() + static_cast<std::ptrdiff_t>(at + n));
  };
  std::size_t at = 4;  // body offsets, XCDR1 alignment from the body's start
  auto field = [&](std::size_t n) {
    while ((at - 4) % n) ++at;
    swap(at, n);
    at += n;
  };
  auto string = [&](const std::string& s) {
    field(4);
    at += s.size() + 1;
  };
  string(m.sender), field(4), string(m.action), field(4), field(8), field(8), field(8);
  ASSERT_EQ(at, bytes.size());
  bytes[1] = 0x00;  // CDR_BE
  std::string why;
  const auto back = decode_command(bytes, &why);
  ASSERT_TRUE(back) << why;
  EXPECT_EQ(back->sender, m.sender);
  EXPECT_EQ(back->code, m.code);
  EXPECT_EQ(back->p, m.p);
  EXPECT_EQ(back->time_ns, m.time_ns);
}

TEST(DdsCommandCdr, MalformedPayloadsAreRefusedWithAReason) {
  const auto good = encode_command(sample());
  std::string why;
  EXPECT_FALSE(decode_command(std::span<const std::uint8_t>(good.data(), 3), &why));
  EXPECT_NE(why.find("header"), std::string::npos) << why;
  // The header alone (found by fuzz/dds_command: the empty body was copied from a null
  // buffer, undefined behaviour that UBSan reports).
  EXPECT_FALSE(decode_command(std::span<const std::uint8_t>(good.data(), 4), &why));
  EXPECT_NE(why.find("no body"), std::string::npos) << why;
  for (std::size_t n = 5; n < good.size(); ++n) {  // every truncation
    why.clear();
    EXPECT_FALSE(decode_command(std::span<const std::uint8_t>(good.data(), n), &why)) << n;
    EXPECT_FALSE(why.empty());
  }
  auto bad = good;
  bad[1] = 0x03;  // PL_CDR_LE: a parameter list, not how a final type arrives
  EXPECT_FALSE(decode_command(bad, &why));
  EXPECT_NE(why.find("encoding"), std::string::npos) << why;
  bad = good;
  bad[4] = 0xff, bad[5] = 0xff, bad[6] = 0xff, bad[7] = 0x7f;  // sender's length far beyond the payload
  EXPECT_FALSE(decode_command(bad, &why));
  EXPECT_NE(why.find("malformed"), std::string::npos) << why;
  bad = good;
  bad[4 + 4 + sample().sender.size()] = 'x';  // sender's terminating NUL
  EXPECT_FALSE(decode_command(bad, &why));
}

// Found by fuzz/dds_command (ASan: SEGV inside libddsc, where the copy ended at a page):
// Cyclone 0.10.2 normalises this 64-byte XCDR2 body as valid having read 68 bytes.
TEST(DdsCommandCdr, ABodyCycloneReadsPastIsRefused) {
  const std::vector<std::uint8_t> payload = {
      0x00, 0x07, 0x00, 0x00, 0x11, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x43, 0x74, 0x72, 0x69,
      0x67, 0x67, 0x65, 0x72, 0x2d, 0x32, 0x36, 0x00, 0x00, 0x00, 0x4b, 0x00, 0x00, 0x00, 0x00, 0x08, 0x00,
      0x00, 0x00, 0x67, 0x67, 0x65, 0x72, 0x00, 0x65, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x3b, 0x00,
      0x00, 0xf8, 0x7f, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0xcd, 0x3f, 0x5b, 0x07, 0x80, 0x00, 0x00, 0x00};
  std::string why;
  EXPECT_FALSE(decode_command(payload, &why));
  EXPECT_NE(why.find("read past its end"), std::string::npos) << why;
}

}  // namespace
}  // namespace eical::drivers::dds
