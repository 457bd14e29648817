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
  int code;  // 101..103
  double p;  // NaN when absent
  std::uint8_t sequence;
};

// nullopt for frames that are not trigger frames (other id, bad length or code).
std::optional<CanTrigger> parse_can_trigger(const can_frame& frame, std::uint32_t trigger_id);
can_frame make_can_trigger(std::uint32_t trigger_id, int code, std::uint8_t sequence, double p = std::nan(""));

struct CanTriggerEvent {
  CanTrigger trigger;
  std::int64_t time_ns;  // CLOCK_MONOTONIC of the frame's reception (kernel timestamp)
};

class CanTriggerInput {
 public:
  // Opens a raw CAN socket on `interface` filtered to `trigger_id`; throws
  // std::runtime_error naming the cause (e.g. no SocketCAN in this kernel).
  CanTriggerInput(const std::string& interface, std::uint32_t trigger_id);
  // Takes an open socket that delivers one can_frame per message (a CAN_RAW socket, or a
  // socketpair(AF_UNIX, SOCK_SEQPACKET) in tests and CAN gateways).
  static CanTriggerInput from_socket(int fd, std::uint32_t trigger_id);
  ~CanTriggerInput();
  CanTriggerInput(CanTriggerInput&& other) noexcept;
  CanTriggerInput(const CanTriggerInput&) = delete;
  CanTriggerInput& operator=(const CanTriggerInput&) = delete;
  CanTriggerInput& operator=(CanTriggerInput&&) = delete;

  [[nodiscard]] int fd() const { return fd_; }
  // Waits up to timeout_ms for a trigger frame. The time is the kernel's receive
  // timestamp (SO_TIMESTAMPNS, CLOCK_REALTIME, moved onto CLOCK_MONOTONIC by the current
  // difference of the two clocks), or the read time when the socket gives none. Frames with
  // another id, a bad layout, or a repeated sequence number (a retransmission) are skipped.
  std::optional<CanTriggerEvent> next(int timeout_ms);
  [[nodiscard]] std::uint64_t frames_ignored() const noexcept { return ignored_; }

 private:
  CanTriggerInput(int fd, std::uint32_t trigger_id, bool) : fd_(fd), id_(trigger_id) {}
  int fd_ = -1;
  std::uint32_t id_;
  int last_seq_ = -1;
  std::uint64_t ignored_ = 0;
};

}  // namespace eical::drivers
