#pragma once
// NC trigger frames on CAN (SocketCAN). Frame layout (11-bit id from the config, DLC 8):
//   byte 0: M-number − 100 (1 = M101 tare/start, 2 = M102 segment, 3 = M103 stop)
//   byte 1: sequence counter (wraps; a repeated value is a retransmission and ignored)
//   bytes 2–5: P word × 1000 as int32 little-endian (0x80000000 = absent)
//   bytes 6–7: reserved, 0
// Parsing is pure logic (tested on byte frames); CanTriggerInput owns the socket.
#include <linux/can.h>

#include <cmath>
#include <cstdint>
#include <optional>
#include <string>

namespace eical::drivers {

struct CanTrigger {
  int code;       // 101..103
  double p;       // NaN when absent
  std::uint8_t sequence;
};

// nullopt for frames that are not trigger frames (other id, bad length or code).
std::optional<CanTrigger> parse_can_trigger(const can_frame& frame, std::uint32_t trigger_id);
can_frame make_can_trigger(std::uint32_t trigger_id, int code, std::uint8_t sequence, double p = std::nan(""));

class CanTriggerInput {
 public:
  // Opens a raw CAN socket on `interface` filtered to `trigger_id`; throws
  // std::runtime_error naming the cause (e.g. no SocketCAN in this kernel).
  CanTriggerInput(const std::string& interface, std::uint32_t trigger_id);
  ~CanTriggerInput();
  [[nodiscard]] int fd() const { return fd_; }
  // Waits up to timeout_ms for a trigger frame; the CLOCK_MONOTONIC receive time in ns.
  std::optional<std::pair<CanTrigger, std::int64_t>> next(int timeout_ms);

 private:
  int fd_ = -1;
  std::uint32_t id_;
  int last_seq_ = -1;
};

}  // namespace eical::drivers
