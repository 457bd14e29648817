#include "drivers/gpio/gpio_trigger.hpp"

#include "dsp/core/frame.hpp"

#include <gpiod.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>

namespace eical::drivers {
namespace {

class LibgpiodLines final : public GpioEventSource {
 public:
  LibgpiodLines(const std::string& chip, const std::array<int, 3>& lines) {
    chip_ = gpiod_chip_open_lookup(chip.c_str());
    if (!chip_) throw std::runtime_error("gpio: cannot open " + chip + ": " + std::strerror(errno));
    gpiod_line_bulk_init(&bulk_);
    for (int offset : lines) {
      gpiod_line* line = gpiod_chip_get_line(chip_, static_cast<unsigned>(offset));
      if (!line) {
        const int err = errno;
        release();
        throw std::runtime_error("gpio: " + chip + " has no line " + std::to_string(offset) + ": " +
                                 std::strerror(err));
      }
      if (gpiod_line_request_rising_edge_events(line, "eicald") != 0) {
        const int err = errno;
        release();
        throw std::runtime_error("gpio: cannot request edges on line " + std::to_string(offset) + " of " + chip + ": " +
                                 std::strerror(err));
      }
      gpiod_line_bulk_add(&bulk_, line);
    }
  }
  ~LibgpiodLines() override { release(); }

  std::optional<GpioLineEvent> wait(int timeout_ms) override {
    timespec to{timeout_ms / 1000, static_cast<long>(timeout_ms % 1000) * 1000000L};
    gpiod_line_bulk events;
    if (gpiod_line_event_wait_bulk(&bulk_, &to, &events) <= 0) return std::nullopt;
    gpiod_line* line = gpiod_line_bulk_get_line(&events, 0);
    gpiod_line_event ev{};
    if (gpiod_line_event_read(line, &ev) != 0) return std::nullopt;
    return GpioLineEvent{gpiod_line_offset(line), ev.event_type == GPIOD_LINE_EVENT_RISING_EDGE,
                         static_cast<std::int64_t>(ev.ts.tv_sec) * 1000000000 + ev.ts.tv_nsec};
  }

 private:
  void release() noexcept {
    if (chip_) {
      if (gpiod_line_bulk_num_lines(&bulk_) > 0) gpiod_line_release_bulk(&bulk_);
      gpiod_chip_close(chip_);
      chip_ = nullptr;
    }
  }
  gpiod_chip* chip_ = nullptr;
  gpiod_line_bulk bulk_{};
};

}  // namespace

std::unique_ptr<GpioEventSource> open_gpio_lines(const std::string& chip, const std::array<int, 3>& lines) {
  return std::make_unique<LibgpiodLines>(chip, lines);
}

GpioTriggerInput::GpioTriggerInput(std::unique_ptr<GpioEventSource> events, const std::array<int, 3>& lines,
                                   std::int64_t debounce_ns)
    : events_(std::move(events)), lines_(lines), debounce_ns_(debounce_ns) {}

GpioTriggerInput::GpioTriggerInput(const std::string& chip, const std::array<int, 3>& lines)
    : GpioTriggerInput(open_gpio_lines(chip, lines), lines) {}

std::optional<GpioEdge> GpioTriggerInput::next(int timeout_ms) {
  const auto ev = events_->wait(timeout_ms);
  if (!ev || !ev->rising) return std::nullopt;
  for (std::size_t k = 0; k < lines_.size(); ++k) {
    if (static_cast<unsigned>(lines_[k]) != ev->offset) continue;
    if (last_ns_[k] >= 0 && ev->time_ns - last_ns_[k] < debounce_ns_) {
      ++bounces_;
      return std::nullopt;
    }
    last_ns_[k] = ev->time_ns;
    return GpioEdge{dsp::trigger::program_start + static_cast<int>(k), ev->time_ns};
  }
  return std::nullopt;
}

}  // namespace eical::drivers
