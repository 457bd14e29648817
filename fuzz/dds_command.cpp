// Fuzz target: a DDS Command payload (encapsulation header + CDR of eical::msg::Command)
// through drivers::dds::decode_command: Cyclone DDS' validation of received data against
// the idlc-generated type, the read into the generated C struct and the conversion to the
// CommandMsg eicald's command handler gets. A payload that is accepted must encode again
// to bytes that decode to the same command.
#include "drivers/dds/command_cdr.hpp"
#include "fuzz/fuzz_support.hpp"

#include <cstring>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace eical;
  std::string why;
  const auto cmd = drivers::dds::decode_command({data, size}, &why);
  if (!cmd) {
    if (why.empty()) eical::fuzz::finding("a refused payload without a reason");
    return 0;
  }
  const auto again = drivers::dds::decode_command(drivers::dds::encode_command(*cmd), &why);
  if (!again) eical::fuzz::finding("an accepted command does not survive encode + decode: " + why);
  const auto bits_equal = [](double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; };
  if (again->sender != cmd->sender || again->action != cmd->action || again->request_id != cmd->request_id ||
      again->code != cmd->code || !bits_equal(again->p, cmd->p) || !bits_equal(again->q, cmd->q) ||
      again->time_ns != cmd->time_ns)
    eical::fuzz::finding("encode + decode changed the command");
  return 0;
}
