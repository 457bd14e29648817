#include "drivers/dds/command_cdr.hpp"

#include "drivers/dds/idl_convert.hpp"

#include <dds/dds.h>
#include <dds/ddsi/ddsi_cdrstream.h>

#include <cstring>

namespace eical::drivers::dds {
namespace {

// Encapsulation identifiers (DDS-XTypes 1.3 §7.6.3.1.2, big-endian on the wire) of the
// plain encodings a final type arrives in; parameter-list and delimited forms belong to
// mutable and appendable types and are refused, as Cyclone refuses an encoding that does
// not match the type.
constexpr std::uint16_t kCdrBe = 0x0000, kCdrLe = 0x0001, kCdr2Be = 0x0006, kCdr2Le = 0x0007;
constexpr std::uint32_t kXcdr1 = 1, kXcdr2 = 2;
constexpr std::size_t kHeaderBytes = 4;
// A Command is two short strings and five numbers; anything near this is not one.
constexpr std::size_t kMaxPayloadBytes = 64 * 1024;

std::optional<CommandMsg> refuse(std::string* why, const char* reason) {
  if (why) *why = reason;
  return std::nullopt;
}

}  // namespace

std::optional<CommandMsg> decode_command(std::span<const std::uint8_t> payload, std::string* why) {
  if (payload.size() < kHeaderBytes) return refuse(why, "shorter than the 4-byte encapsulation header");
  if (payload.size() > kMaxPayloadBytes) return refuse(why, "larger than 64 KiB");
  const auto id = static_cast<std::uint16_t>(payload[0] << 8 | payload[1]);
  const std::uint32_t pad = payload[3] & 3u;  // options: bytes of padding at the end
  if (id != kCdrBe && id != kCdrLe && id != kCdr2Be && id != kCdr2Le) return refuse(why, "not a plain CDR encoding");
  const bool little = id == kCdrLe || id == kCdr2Le;
  const std::uint32_t xcdr = id == kCdrBe || id == kCdrLe ? kXcdr1 : kXcdr2;
  const auto size = static_cast<std::uint32_t>(payload.size() - kHeaderBytes);
  if (size == 0) return refuse(why, "no body after the encapsulation header");
  if (pad > size) return refuse(why, "padding longer than the body");
  // Cyclone normalises in place (byte order) and needs the body 8-byte aligned. Cyclone
  // 0.10.2 (Debian 12) reads up to 4 bytes beyond the size it is given on some malformed
  // XCDR2 bodies and then reports having consumed them (fuzz/dds_command: 68 of a 64-byte
  // body; a segfault where the buffer ended at a page): the body gets zeroed slack behind
  // it, and an offset past the end is refused.
  constexpr std::size_t kSlackWords = 2;
  std::vector<std::uint64_t> body((size + 7) / 8 + kSlackWords, 0);
  std::memcpy(body.data(), payload.data() + kHeaderBytes, size);
  char* data = reinterpret_cast<char*>(body.data());
  std::uint32_t off = 0;
  const bool swap = little != (DDSRT_ENDIAN == DDSRT_LITTLE_ENDIAN);
  if (!dds_stream_normalize_data(data, &off, size - pad, swap, xcdr, eical_msg_Command_desc.m_ops))
    return refuse(why, "malformed CDR for eical::msg::Command");
  if (off > size - pad) return refuse(why, "malformed CDR for eical::msg::Command (read past its end)");
  dds_istream_t is;
  dds_istream_init(&is, size - pad, data, xcdr);
  eical_msg_Command sample{};
  (void)dds_stream_read(&is, reinterpret_cast<char*>(&sample), eical_msg_Command_desc.m_ops);
  dds_istream_fini(&is);
  CommandMsg out = from_idl(sample);
  dds_stream_free_sample(&sample, eical_msg_Command_desc.m_ops);
  return out;
}

std::vector<std::uint8_t> encode_command(const CommandMsg& m) {
  eical_msg_Command s{};
  s.sender = const_cast<char*>(m.sender.c_str()), s.action = const_cast<char*>(m.action.c_str());
  s.request_id = m.request_id, s.code = m.code, s.p = m.p, s.q = m.q, s.time_ns = m.time_ns;
  dds_ostreamLE_t os;
  dds_ostreamLE_init(&os, 0, kXcdr1);
  (void)dds_stream_writeLE(&os, reinterpret_cast<const char*>(&s), eical_msg_Command_desc.m_ops);
  std::vector<std::uint8_t> out(kHeaderBytes + os.x.m_index, 0);
  out[1] = static_cast<std::uint8_t>(kCdrLe);  // header: CDR_LE (big-endian identifier), no padding
  std::memcpy(out.data() + kHeaderBytes, os.x.m_buffer, os.x.m_index);
  dds_ostreamLE_fini(&os);
  return out;
}

}  // namespace eical::drivers::dds
