#include "drivers/gpio/gpio_trigger.hpp"

#include <gpiod.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>

namespace eical::drivers {

GpioTriggerInput::GpioTriggerInput(const std::string& chip, const std::array<int, 3>& lines) : lines_(lines) {
  chip_ = gpiod_chip_open_lookup(chip.c_str());
  if (!chip_) throw std::runtime_error("gpio: cannot open " + chip + ": " + std::strerror(errno));
  auto* bulk = new gpiod_line_bulk;
  gpiod_line_bulk_init(bulk);
  bulk_ = bulk;
  for (int offset : lines_) {
    gpiod_line* line = gpiod_chip_get_line(chip_, static_cast<unsigned>(offset));
    if (!line) throw std::runtime_error("gpio: " + chip + " has no line " + std::to_string(offset) + ": " + std::strerror(errno));
    if (gpiod_line_request_rising_edge_events(line, "eicald") != 0)
      throw std::runtime_error("gpio: cannot request edges on line " + std::to_string(offset) + ": " + std::strerror(errno));
    gpiod_line_bulk_add(bulk, line);
  }
}

GpioTriggerInput::~GpioTriggerInput() {
  if (bulk_) {
    auto* bulk = static_cast<gpiod_line_bulk*>(bulk_);
    gpiod_line_release_bulk(bulk);
    delete bulk;
  }
  if (chip_) gpiod_chip_close(chip_);
}

std::optional<GpioEdge> GpioTriggerInput::next(int timeout_ms) {
  auto* bulk = static_cast<gpiod_line_bulk*>(bulk_);
  timespec to{timeout_ms / 1000, static_cast<long>(timeout_ms % 1000) * 1000000L};
  gpiod_line_bulk events;
  if (gpiod_line_event_wait_bulk(bulk, &to, &events) <= 0) return std::nullopt;
  gpiod_line* line = gpiod_line_bulk_get_line(&events, 0);
  gpiod_line_event ev{};
  if (gpiod_line_event_read(line, &ev) != 0) return std::nullopt;
  const unsigned offset = gpiod_line_offset(line);
  for (int k = 0; k < 3; ++k)
    if (static_cast<unsigned>(lines_[static_cast<std::size_t>(k)]) == offset)
      return GpioEdge{101 + k, static_cast<std::int64_t>(ev.ts.tv_sec) * 1000000000 + ev.ts.tv_nsec};
  return std::nullopt;
}

}  // namespace eical::drivers
