#include "drivers/can/can_trigger.hpp"

#include <linux/can/raw.h>
#include <net/if.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <ctime>
#include <stdexcept>

namespace eical::drivers {

std::optional<CanTrigger> parse_can_trigger(const can_frame& frame, std::uint32_t trigger_id) {
  if ((frame.can_id & CAN_EFF_FLAG) || (frame.can_id & CAN_RTR_FLAG) || (frame.can_id & CAN_SFF_MASK) != trigger_id ||
      frame.len != 8)
    return std::nullopt;
  if (frame.data[0] < 1 || frame.data[0] > 3) return std::nullopt;
  const auto raw = static_cast<std::int32_t>(
      static_cast<std::uint32_t>(frame.data[2]) | static_cast<std::uint32_t>(frame.data[3]) << 8 |
      static_cast<std::uint32_t>(frame.data[4]) << 16 | static_cast<std::uint32_t>(frame.data[5]) << 24);
  const double p = raw == INT32_MIN ? std::nan("") : raw / 1000.0;
  return CanTrigger{100 + frame.data[0], p, frame.data[1]};
}

can_frame make_can_trigger(std::uint32_t trigger_id, int code, std::uint8_t sequence, double p) {
  can_frame f{};
  f.can_id = trigger_id & CAN_SFF_MASK;
  f.len = 8;
  f.data[0] = static_cast<std::uint8_t>(code - 100);
  f.data[1] = sequence;
  const std::int32_t raw = std::isnan(p) ? INT32_MIN : static_cast<std::int32_t>(std::lround(p * 1000.0));
  for (int b = 0; b < 4; ++b) f.data[2 + b] = static_cast<std::uint8_t>(static_cast<std::uint32_t>(raw) >> (8 * b));
  return f;
}

CanTriggerInput::CanTriggerInput(const std::string& interface, std::uint32_t trigger_id) : id_(trigger_id) {
  fd_ = ::socket(PF_CAN, SOCK_RAW | SOCK_CLOEXEC, CAN_RAW);
  if (fd_ < 0)
    throw std::runtime_error(std::string("can: SocketCAN is not available in this kernel (socket(PF_CAN): ") +
                             std::strerror(errno) + ")");
  const unsigned idx = ::if_nametoindex(interface.c_str());
  if (idx == 0) {
    const int err = errno;
    ::close(fd_);
    throw std::runtime_error("can: no CAN interface '" + interface + "' (" + std::strerror(err) + ")");
  }
  can_filter filter{trigger_id & CAN_SFF_MASK, CAN_SFF_MASK | CAN_EFF_FLAG | CAN_RTR_FLAG};
  ::setsockopt(fd_, SOL_CAN_RAW, CAN_RAW_FILTER, &filter, sizeof filter);
  const int on = 1;
  (void)::setsockopt(fd_, SOL_SOCKET, SO_TIMESTAMPNS, &on, sizeof on);
  sockaddr_can addr{};
  addr.can_family = AF_CAN;
  addr.can_ifindex = static_cast<int>(idx);
  if (::bind(fd_, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) {
    const int err = errno;
    ::close(fd_);
    throw std::runtime_error("can: cannot bind to '" + interface + "': " + std::strerror(err));
  }
}

CanTriggerInput CanTriggerInput::from_socket(int fd, std::uint32_t trigger_id) {
  const int on = 1;
  (void)::setsockopt(fd, SOL_SOCKET, SO_TIMESTAMPNS, &on, sizeof on);  // where the socket supports it
  return CanTriggerInput(fd, trigger_id, true);
}

CanTriggerInput::CanTriggerInput(CanTriggerInput&& other) noexcept
    : fd_(other.fd_), id_(other.id_), last_seq_(other.last_seq_), ignored_(other.ignored_) {
  other.fd_ = -1;
}

CanTriggerInput::~CanTriggerInput() {
  if (fd_ >= 0) ::close(fd_);
}

std::optional<CanTriggerEvent> CanTriggerInput::next(int timeout_ms) {
  pollfd p{fd_, POLLIN, 0};
  if (::poll(&p, 1, timeout_ms) <= 0) return std::nullopt;
  can_frame f{};
  iovec iov{&f, sizeof f};
  alignas(cmsghdr) char control[CMSG_SPACE(sizeof(timespec))];
  msghdr msg{};
  msg.msg_iov = &iov;
  msg.msg_iovlen = 1;
  msg.msg_control = control;
  msg.msg_controllen = sizeof control;
  if (::recvmsg(fd_, &msg, 0) != static_cast<ssize_t>(sizeof f)) return std::nullopt;
  timespec mono{}, real{};
  clock_gettime(CLOCK_MONOTONIC, &mono);
  clock_gettime(CLOCK_REALTIME, &real);
  const auto ns = [](const timespec& t) { return static_cast<std::int64_t>(t.tv_sec) * 1000000000 + t.tv_nsec; };
  std::int64_t t_ns = ns(mono);
  for (cmsghdr* c = CMSG_FIRSTHDR(&msg); c; c = CMSG_NXTHDR(&msg, c))
    if (c->cmsg_level == SOL_SOCKET && c->cmsg_type == SCM_TIMESTAMPNS) {
      timespec kernel{};
      std::memcpy(&kernel, CMSG_DATA(c), sizeof kernel);
      const std::int64_t age_ns = ns(real) - ns(kernel);
      if (age_ns >= 0 && age_ns < 1'000'000'000) t_ns -= age_ns;  // a clock step makes it implausible: read time
    }
  auto t = parse_can_trigger(f, id_);
  if (!t || t->sequence == last_seq_) {  // not ours, or a retransmission
    ++ignored_;
    return std::nullopt;
  }
  last_seq_ = t->sequence;
  return CanTriggerEvent{*t, t_ns};
}

}  // namespace eical::drivers
