#pragma once
// NC trigger inputs on GPIO lines (libgpiod 1.6): a PLC output per M-function (M101,
// M102, M103), rising edges with the kernel's CLOCK_MONOTONIC timestamp, which the
// daemon maps onto the DAQ sample clock. Absent chips are a clear error at start.
#include <array>
#include <cstdint>
#include <optional>
#include <string>

struct gpiod_chip;
struct gpiod_line_bulk;

namespace eical::drivers {

struct GpioEdge {
  int code;              // 101, 102, 103
  std::int64_t time_ns;  // CLOCK_MONOTONIC of the edge (kernel timestamp)
};

class GpioTriggerInput {
 public:
  // Throws std::runtime_error, e.g. "gpio: cannot open gpiochip0: No such file or directory".
  GpioTriggerInput(const std::string& chip, const std::array<int, 3>& lines);
  ~GpioTriggerInput();
  std::optional<GpioEdge> next(int timeout_ms);

 private:
  gpiod_chip* chip_ = nullptr;
  std::array<int, 3> lines_;
  void* bulk_ = nullptr;  // gpiod_line_bulk, heap-held to keep the header free of gpiod.h
};

}  // namespace eical::drivers
