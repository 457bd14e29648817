#pragma once
// The reading half of LinuxCNC's servo stream (integrations/linuxcnc: HAL sampler →
// eical-halsampler → a named pipe), shared by the `linuxcnc` source (the positions drive
// the simulated machine) and the servo set-point feed (the positions are the set-point
// next to a DAQ). It creates and opens the pipe, waits for data with poll() — a wake fd
// interrupts it, no polling sleeps —, splits and parses the lines, keeps the servo clock
// (cycle number ↔ CLOCK_MONOTONIC) and fills short runs of lost cycles by linear
// interpolation. Storage is allocated in the constructor; per line nothing allocates.
#include "drivers/source/sample_clock.hpp"
#include "drivers/source/servo_stream.hpp"

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace eical::drivers {

struct ServoStreamOptions {
  std::filesystem::path fifo = "/run/eical/linuxcnc-servo.fifo";
  double servo_rate_hz = 1000.0;       // [EMCMOT]SERVO_PERIOD
  std::size_t max_fill_cycles = 1000;  // lost cycles up to this many are interpolated; more are an error
};

// One servo cycle as delivered to the consumer.
struct ServoCycle {
  std::int64_t number = 0;
  double cmd_mm[3] = {};
  double fb_mm[3] = {};
  std::uint32_t marker = 0;
  bool filled = false;  // interpolated for a lost cycle
};

struct ServoStreamStats {
  std::uint64_t lines = 0, lost_cycles = 0, overrun_lines = 0;
  std::int64_t first_number = -1, last_number = -1;
};

class ServoStreamReader {
 public:
  enum class Status {
    data,     // lines were read (possibly only part of one)
    timeout,  // nothing within the timeout
    closed,   // the writer closed the pipe (LinuxCNC stopped or eical-halsampler exited)
    woken,    // wake() was called
    error,    // malformed or inconsistent stream: error() says why
  };

  explicit ServoStreamReader(ServoStreamOptions options);
  ~ServoStreamReader();
  ServoStreamReader(const ServoStreamReader&) = delete;
  ServoStreamReader& operator=(const ServoStreamReader&) = delete;

  // Creates the named pipe if absent (mode 0666: LinuxCNC may run as another user) and
  // opens it without blocking (a pipe without a writer must not hang); SourceError naming
  // the cause otherwise. Reopening starts a new stream (cycle numbers, clock).
  void open();
  void close() noexcept;
  // A new stream on the open pipe (after error()): cycle numbers and the clock start over.
  void restart() noexcept;
  // Any thread: makes a waiting read() return `woken`.
  void wake() noexcept;

  // Waits up to `timeout_ms` for data and calls `on_cycle(const ServoCycle&)` for every
  // complete line (lost cycles first, as filled cycles).
  template <class OnCycle>
  Status read(int timeout_ms, OnCycle&& on_cycle) {
    const Status s = wait_and_read(timeout_ms);
    if (s != Status::data) return s;
    std::size_t start = 0;
    for (std::size_t i = 0; i < used_; ++i) {
      if (buf_[i] != '\n') continue;
      const std::string_view line(buf_.data() + start, i - start);
      start = i + 1;
      ServoCycle cycles[2];
      int n_fill = 0;
      const LineResult r = take_line(line, cycles[1], n_fill);
      if (r == LineResult::bad) return keep_partial(start), Status::error;
      if (r == LineResult::skip) continue;
      for (int k = 1; k <= n_fill; ++k) {
        cycles[0] = fill(k, n_fill, cycles[1]);
        on_cycle(static_cast<const ServoCycle&>(cycles[0]));
      }
      remember(cycles[1]);
      on_cycle(static_cast<const ServoCycle&>(cycles[1]));
    }
    if (!keep_partial(start)) return Status::error;
    return Status::data;
  }

  [[nodiscard]] const std::string& error() const noexcept { return error_; }
  [[nodiscard]] const ServoStreamStats& stats() const noexcept { return stats_; }  // reader thread
  [[nodiscard]] SampleClock& clock() noexcept { return clock_; }
  [[nodiscard]] const SampleClock& clock() const noexcept { return clock_; }
  [[nodiscard]] const ServoStreamOptions& options() const noexcept { return options_; }

 private:
  enum class LineResult { cycle, skip, bad };
  Status wait_and_read(int timeout_ms);
  LineResult take_line(std::string_view line, ServoCycle& out, int& n_fill);
  [[nodiscard]] ServoCycle fill(int k, int n_fill, const ServoCycle& next) const noexcept;
  void remember(const ServoCycle& c) noexcept { last_ = c; }
  bool keep_partial(std::size_t start) noexcept;

  ServoStreamOptions options_;
  int fd_ = -1, wake_fd_ = -1;
  std::vector<char> buf_;
  std::size_t used_ = 0;
  std::int64_t arrival_ns_ = 0;
  ServoCycle last_;
  ServoStreamStats stats_;
  SampleClock clock_;
  std::string error_;
};

}  // namespace eical::drivers
