// Fuzz target: an NC trigger frame on CAN (drivers/can: SocketCAN frame, id 0x1E0 as in
// config/eicald.toml) through drivers::parse_can_trigger. The input is the raw can_frame
// (16 bytes, as a read() from the socket delivers it). An accepted frame carries M101..M103
// and a P word that is absent or finite, and make_can_trigger writes it back to a frame
// that parses to the same trigger.
#include "drivers/can/can_trigger.hpp"
#include "fuzz/fuzz_support.hpp"

#include <cstring>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace eical;
  constexpr std::uint32_t kId = 0x1E0;
  can_frame frame{};
  std::memcpy(&frame, data, std::min(size, sizeof frame));
  const auto t = drivers::parse_can_trigger(frame, kId);
  if (!t) return 0;
  if (t->code < 101 || t->code > 103) fuzz::finding("a trigger code outside M101..M103");
  if (!std::isnan(t->p) && !std::isfinite(t->p)) fuzz::finding("a P word that is not finite");
  const auto back = drivers::parse_can_trigger(drivers::make_can_trigger(kId, t->code, t->sequence, t->p), kId);
  if (!back || back->code != t->code || back->sequence != t->sequence || (std::isnan(t->p) != std::isnan(back->p)) ||
      (!std::isnan(t->p) && back->p != t->p))
    fuzz::finding("make_can_trigger does not write back what parse_can_trigger read");
  return 0;
}
