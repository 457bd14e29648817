#include "drivers/usb_daq/daq_stream_source.hpp"

#include "drivers/source/stamped_source.hpp"

#include <fcntl.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>
#include <algorithm>
#include <cerrno>
#include <cstring>

namespace eical::drivers {
namespace {

constexpr int kReadWaitMs = 100;  // bounded: the pump checks its stop flag between reads

int open_socket(const std::string& path) {
  const int fd = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC | SOCK_NONBLOCK, 0);
  if (fd < 0) throw SourceError(std::string("daq_stream: socket: ") + std::strerror(errno));
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  if (path.size() >= sizeof addr.sun_path) {
    ::close(fd);
    throw SourceError("daq_stream: socket path too long: " + path);
  }
  std::memcpy(addr.sun_path, path.c_str(), path.size() + 1);
  if (::connect(fd, reinterpret_cast<const sockaddr*>(&addr), sizeof addr) != 0 && errno != EINPROGRESS) {
    const int err = errno;
    ::close(fd);
    throw SourceError("daq_stream: cannot connect to the DAQ socket " + path + ": " + std::strerror(err));
  }
  return fd;
}

int open_fifo(const std::filesystem::path& p) {
  const std::string path = p.string();
  std::error_code ec;
  std::filesystem::create_directories(p.parent_path(), ec);
  if (::mkfifo(path.c_str(), 0660) != 0 && errno != EEXIST)
    throw SourceError("daq_stream: cannot create the pipe " + path + ": " + std::strerror(errno));
  // Non-blocking: a pipe without a writer must not hang; poll() waits for the writer.
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) throw SourceError("daq_stream: cannot open " + path + ": " + std::strerror(errno));
  return fd;
}

}  // namespace

DaqStreamSource::DaqStreamSource(dsp::RunMeta meta, DaqStreamOptions options)
    : meta_(std::move(meta)), options_(std::move(options)), frames_(static_cast<int>(meta_.psd.size())) {}

DaqStreamSource::~DaqStreamSource() { close(); }

void DaqStreamSource::close() noexcept {
  if (fd_ >= 0) ::close(fd_), fd_ = -1;
}

void DaqStreamSource::open() {
  close();
  frames_.reset();
  const std::string path = options_.path.string();
  struct stat st {};
  const bool exists = ::stat(path.c_str(), &st) == 0;
  if (exists && S_ISSOCK(st.st_mode)) {
    fd_ = open_socket(path);
  } else if (!exists || S_ISFIFO(st.st_mode)) {
    fd_ = open_fifo(options_.path);
  } else {
    throw SourceError("daq_stream: " + path + " is neither a named pipe nor a socket");
  }
  const std::int64_t deadline = monotonic_ns() + static_cast<std::int64_t>(options_.connect_timeout_s * 1e9);
  while (frames_.size() == 0) {
    const std::int64_t left_ms = (deadline - monotonic_ns()) / 1000000;
    if (left_ms <= 0 || !pull(static_cast<int>(std::min<std::int64_t>(left_ms, kReadWaitMs)))) {
      if (monotonic_ns() < deadline) continue;
      close();
      throw SourceError("daq_stream: no DAQ packets on " + path + " within " +
                        std::to_string(options_.connect_timeout_s) + " s (is the DAQ or its bridge writing it?)");
    }
  }
  last_data_ns_ = monotonic_ns();
}

bool DaqStreamSource::pull(int timeout_ms) {
  pollfd p{fd_, POLLIN, 0};
  const int r = ::poll(&p, 1, timeout_ms);
  if (r < 0 && errno != EINTR) throw SourceError(std::string("daq_stream: poll: ") + std::strerror(errno));
  if (r <= 0) return false;
  std::uint8_t buf[16384];
  const ssize_t got = ::read(fd_, buf, sizeof buf);
  if (got < 0) {
    if (errno == EAGAIN || errno == EINTR) return false;
    throw SourceError(std::string("daq_stream: read: ") + std::strerror(errno));
  }
  if (got == 0) throw SourceError("daq_stream: the DAQ stream " + options_.path.string() + " was closed by its writer");
  frames_.feed(std::span<const std::uint8_t>(buf, static_cast<std::size_t>(got)));
  publish_counters();
  return true;
}

std::size_t DaqStreamSource::read(std::span<dsp::Frame> out) {
  if (frames_.size() < out.size()) {
    if (pull(frames_.size() > 0 ? 0 : kReadWaitMs)) {
      last_data_ns_ = monotonic_ns();
    } else if (frames_.size() == 0 &&
               monotonic_ns() - last_data_ns_ > static_cast<std::int64_t>(options_.stall_timeout_s * 1e9)) {
      throw SourceError("daq_stream: no data for " + std::to_string(options_.stall_timeout_s) + " s on " +
                        options_.path.string());
    }
  }
  return frames_.pop(out);
}

void DaqStreamSource::publish_counters() noexcept {
  const auto& s = frames_.stats();
  decode_errors_.store(s.crc_errors + s.unknown_packets, std::memory_order_relaxed);
  lost_samples_.store(s.lost_samples, std::memory_order_relaxed);
  dropped_.store(frames_.dropped(), std::memory_order_relaxed);
}

SourceCounters DaqStreamSource::counters() const {
  SourceCounters c;
  c.decode_errors = decode_errors_.load(std::memory_order_relaxed);
  c.lost_samples = lost_samples_.load(std::memory_order_relaxed);
  c.dropped_frames = dropped_.load(std::memory_order_relaxed);
  return c;
}

}  // namespace eical::drivers
