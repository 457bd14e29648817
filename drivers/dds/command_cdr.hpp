#pragma once
// The Command topic's payload as it arrives from the wire: the 4-byte encapsulation header
// (encoding identifier, options) and the CDR body of eical::msg::Command. decode_command
// checks it as Cyclone DDS does on receipt (dds_stream_normalize_data against the
// idlc-generated type's ops: lengths, string terminators, bounds) and reads it into the
// CommandMsg that eicald's command handler gets from Bus::take_command. Malformed bytes are
// refused with a reason, never read past. The fuzz target fuzz/dds_command.cpp drives it.
#include "drivers/dds/messages.hpp"

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace eical::drivers::dds {

// nullopt and `why` (when given) for bytes that are not a Command in plain (X)CDR.
std::optional<CommandMsg> decode_command(std::span<const std::uint8_t> payload, std::string* why = nullptr);

// What a writer sends: CDR_LE (XCDR1) with its header (tests, the fuzz corpus).
std::vector<std::uint8_t> encode_command(const CommandMsg& m);

}  // namespace eical::drivers::dds
