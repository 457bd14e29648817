#include "drivers/source/servo_stream_reader.hpp"

#include "drivers/source/source.hpp"
#include "drivers/source/stamped_source.hpp"

#include <fcntl.h>
#include <poll.h>
#include <sys/eventfd.h>
#include <sys/stat.h>
#include <unistd.h>
#include <cerrno>
#include <cstring>

namespace eical::drivers {

ServoStreamReader::ServoStreamReader(ServoStreamOptions options)
    : options_(std::move(options)), buf_(1 << 16), clock_(1.0 / options_.servo_rate_hz) {
  wake_fd_ = ::eventfd(0, EFD_CLOEXEC | EFD_NONBLOCK);
  if (wake_fd_ < 0) throw SourceError(std::string("linuxcnc: eventfd: ") + std::strerror(errno));
}

ServoStreamReader::~ServoStreamReader() {
  close();
  if (wake_fd_ >= 0) ::close(wake_fd_);
}

void ServoStreamReader::open() {
  close();
  const std::string path = options_.fifo.string();
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) {
    if (errno != ENOENT) throw SourceError("linuxcnc: " + path + ": " + std::strerror(errno));
    std::error_code ec;
    std::filesystem::create_directories(options_.fifo.parent_path(), ec);
    // 0666: eical-halsampler runs as LinuxCNC's user; the umask is overridden by chmod.
    if (::mkfifo(path.c_str(), 0666) != 0 && errno != EEXIST)
      throw SourceError("linuxcnc: cannot create the servo stream pipe " + path + ": " + std::strerror(errno));
    (void)::chmod(path.c_str(), 0666);
  } else if (!S_ISFIFO(st.st_mode)) {
    throw SourceError("linuxcnc: " + path + " exists and is not a named pipe (remove it; eicald creates the pipe)");
  }
  // Non-blocking open: a pipe without a writer (LinuxCNC not running) must not hang here.
  fd_ = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd_ < 0) throw SourceError("linuxcnc: cannot open " + path + ": " + std::strerror(errno));
  used_ = 0;
  stats_ = {};
  last_ = {};
  error_.clear();  // the clock keeps the last stream's mapping until the new stream's first line
  std::uint64_t n = 0;
  (void)!::read(wake_fd_, &n, sizeof n);  // a stale wake-up does not end the new stream
}

void ServoStreamReader::restart() noexcept {
  stats_.last_number = -1;
  stats_.first_number = -1;
  last_ = {};
}

void ServoStreamReader::close() noexcept {
  if (fd_ >= 0) ::close(fd_), fd_ = -1;
}

void ServoStreamReader::wake() noexcept {
  const std::uint64_t one = 1;
  (void)!::write(wake_fd_, &one, sizeof one);
}

ServoStreamReader::Status ServoStreamReader::wait_and_read(int timeout_ms) {
  for (;;) {
    pollfd p[2] = {{fd_, POLLIN, 0}, {wake_fd_, POLLIN, 0}};
    const int r = ::poll(p, 2, timeout_ms);
    if (r < 0) {
      if (errno == EINTR) continue;
      error_ = std::string("poll: ") + std::strerror(errno);
      return Status::error;
    }
    if (p[1].revents) {
      std::uint64_t n = 0;
      (void)!::read(wake_fd_, &n, sizeof n);
      return Status::woken;
    }
    if (r == 0) return Status::timeout;
    const ssize_t got = ::read(fd_, buf_.data() + used_, buf_.size() - used_);
    arrival_ns_ = monotonic_ns();
    if (got < 0) {
      if (errno == EAGAIN || errno == EINTR) continue;
      error_ = std::string("read: ") + std::strerror(errno);
      return Status::error;
    }
    if (got == 0) return Status::closed;
    used_ += static_cast<std::size_t>(got);
    return Status::data;
  }
}

ServoStreamReader::LineResult ServoStreamReader::take_line(std::string_view line, ServoCycle& out, int& n_fill) {
  const auto parsed = parse_servo_line(line, error_);
  if (!parsed) {
    error_ = "malformed servo line " + std::to_string(stats_.lines + 1) + ": " + error_ + " in '" +
             std::string(line.substr(0, 120)) + "'";
    return LineResult::bad;
  }
  ++stats_.lines;
  if (parsed->kind == ServoLine::Kind::overrun) {
    ++stats_.overrun_lines;
    return LineResult::skip;
  }
  const ServoSample& s = parsed->sample;
  out.number = s.number;
  for (int a = 0; a < 3; ++a) out.cmd_mm[a] = s.cmd_mm[a], out.fb_mm[a] = s.fb_mm[a];
  out.marker = s.marker;
  out.filled = false;
  n_fill = 0;
  if (stats_.last_number >= 0) {
    if (s.number <= stats_.last_number) {
      error_ = "servo cycle numbers went back from " + std::to_string(stats_.last_number) + " to " +
               std::to_string(s.number) + " (LinuxCNC restarted?)";
      return LineResult::bad;
    }
    if (s.number > stats_.last_number + 1) {
      const auto lost = static_cast<std::size_t>(s.number - stats_.last_number - 1);
      if (lost > options_.max_fill_cycles) {
        error_ = std::to_string(lost) + " servo cycles lost after cycle " + std::to_string(stats_.last_number) +
                 " (more than max_fill_cycles; eicald fell behind or LinuxCNC paused)";
        return LineResult::bad;
      }
      stats_.lost_cycles += lost;
      n_fill = static_cast<int>(lost);
    }
  } else {
    stats_.first_number = s.number;
    clock_.reset();  // a new stream: its own cycle numbers
  }
  clock_.observe(s.number, arrival_ns_);
  stats_.last_number = s.number;
  return LineResult::cycle;
}

ServoCycle ServoStreamReader::fill(int k, int n_fill, const ServoCycle& next) const noexcept {
  ServoCycle c;
  const double u = static_cast<double>(k) / static_cast<double>(n_fill + 1);
  c.number = last_.number + k;
  for (int a = 0; a < 3; ++a) {
    c.cmd_mm[a] = last_.cmd_mm[a] + (next.cmd_mm[a] - last_.cmd_mm[a]) * u;
    c.fb_mm[a] = last_.fb_mm[a] + (next.fb_mm[a] - last_.fb_mm[a]) * u;
  }
  c.marker = last_.marker;
  c.filled = true;
  return c;
}

bool ServoStreamReader::keep_partial(std::size_t start) noexcept {
  if (start > 0) std::memmove(buf_.data(), buf_.data() + start, used_ - start), used_ -= start;
  if (used_ == buf_.size()) {
    error_ = "a servo line longer than " + std::to_string(buf_.size()) + " bytes: not the kit's stream";
    return false;
  }
  return true;
}

}  // namespace eical::drivers
