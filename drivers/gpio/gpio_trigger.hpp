#pragma once
// NC trigger inputs on GPIO lines (libgpiod 1.6): a PLC output per M-function (M101,
// M102, M103), rising edges with the kernel's timestamp — CLOCK_MONOTONIC (the GPIO
// character device stamps line events with ktime_get_ns since Linux 5.7; Debian 12 runs
// 6.1) —, which eicald maps onto the DAQ sample clock. Absent chips are a clear error at
// start. The line events come through GpioEventSource, so the trigger logic (which line is
// which M-function, debouncing) is tested on events without a gpiochip.
#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>

namespace eical::drivers {

struct GpioLineEvent {
  unsigned offset;  // line offset on the chip
  bool rising;
  std::int64_t time_ns;  // kernel timestamp, CLOCK_MONOTONIC
};

class GpioEventSource {
 public:
  virtual ~GpioEventSource() = default;
  // Waits up to timeout_ms for the next line event.
  virtual std::optional<GpioLineEvent> wait(int timeout_ms) = 0;
};

// libgpiod 1.6: rising-edge events of `lines` on `chip` (name, number or path). Throws
// std::runtime_error naming the chip or line, e.g. "gpio: cannot open gpiochip0: No such
// file or directory".
std::unique_ptr<GpioEventSource> open_gpio_lines(const std::string& chip, const std::array<int, 3>& lines);

struct GpioEdge {
  int code;              // 101, 102, 103
  std::int64_t time_ns;  // CLOCK_MONOTONIC of the edge (kernel timestamp)
};

class GpioTriggerInput {
 public:
  // lines: offsets for M101, M102, M103. An edge on the same line within `debounce_ns`
  // of the previous one is contact bounce (a doubled M102 would add a segment): ignored.
  GpioTriggerInput(std::unique_ptr<GpioEventSource> events, const std::array<int, 3>& lines,
                   std::int64_t debounce_ns = 5'000'000);
  // Opens the chip (open_gpio_lines).
  GpioTriggerInput(const std::string& chip, const std::array<int, 3>& lines);

  std::optional<GpioEdge> next(int timeout_ms);
  [[nodiscard]] std::uint64_t bounces() const noexcept { return bounces_; }

 private:
  std::unique_ptr<GpioEventSource> events_;
  std::array<int, 3> lines_;
  std::int64_t debounce_ns_;
  std::array<std::int64_t, 3> last_ns_{-1, -1, -1};
  std::uint64_t bounces_ = 0;
};

}  // namespace eical::drivers
