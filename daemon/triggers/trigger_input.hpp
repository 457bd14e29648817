#pragma once
// A hardware trigger input (GPIO lines, CAN frames) as eicald's listener thread sees it:
// wait for the next M-function with its CLOCK_MONOTONIC time. Opening one whose device is
// absent throws std::runtime_error naming the device (at --check and at start-up).
#include "daemon/config/daemon_config.hpp"
#include "daemon/triggers/trigger_request.hpp"

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace eical::drivers {
class GpioEventSource;
}

namespace eical::daemon {

class TriggerInput {
 public:
  virtual ~TriggerInput() = default;
  [[nodiscard]] virtual std::string name() const = 0;  // "gpio gpiochip0", "can can0"
  // Waits up to timeout_ms; the request's id is filled in by the listener.
  virtual std::optional<TriggerRequest> wait(int timeout_ms) = 0;
  // Events the input received but ignored (bounces, other CAN ids, retransmissions).
  [[nodiscard]] virtual std::uint64_t ignored() const = 0;
};

std::unique_ptr<TriggerInput> make_gpio_input(std::unique_ptr<drivers::GpioEventSource> events,
                                              const TriggerConfig& config, std::string name);
// A socket that delivers one can_frame per message (CAN_RAW, or a socketpair in tests).
std::unique_ptr<TriggerInput> make_can_input_on_socket(int fd, const TriggerConfig& config, std::string name);

// The inputs [triggers] inputs names besides "frame" and "dds": opened now.
using TriggerInputFactory = std::function<std::vector<std::unique_ptr<TriggerInput>>(const TriggerConfig&)>;
std::vector<std::unique_ptr<TriggerInput>> open_trigger_inputs(const TriggerConfig& config);

}  // namespace eical::daemon
