#include "daemon/triggers/trigger_input.hpp"

#include "drivers/can/can_trigger.hpp"
#include "drivers/gpio/gpio_trigger.hpp"

#include <algorithm>
#include <cmath>

namespace eical::daemon {
namespace {

class GpioInput final : public TriggerInput {
 public:
  GpioInput(drivers::GpioTriggerInput in, std::string name) : in_(std::move(in)), name_(std::move(name)) {}
  [[nodiscard]] std::string name() const override { return name_; }
  std::optional<TriggerRequest> wait(int timeout_ms) override {
    const auto e = in_.next(timeout_ms);
    if (!e) return std::nullopt;
    TriggerRequest r;
    r.time_ns = e->time_ns;
    r.code = e->code;
    return r;
  }
  [[nodiscard]] std::uint64_t ignored() const override { return in_.bounces(); }

 private:
  drivers::GpioTriggerInput in_;
  std::string name_;
};

class CanInput final : public TriggerInput {
 public:
  CanInput(drivers::CanTriggerInput in, std::string name) : in_(std::move(in)), name_(std::move(name)) {}
  [[nodiscard]] std::string name() const override { return name_; }
  std::optional<TriggerRequest> wait(int timeout_ms) override {
    const auto e = in_.next(timeout_ms);
    if (!e) return std::nullopt;
    TriggerRequest r;
    r.time_ns = e->time_ns;
    r.code = e->trigger.code;
    r.p = e->trigger.p;
    return r;
  }
  [[nodiscard]] std::uint64_t ignored() const override { return in_.frames_ignored(); }

 private:
  drivers::CanTriggerInput in_;
  std::string name_;
};

std::array<int, 3> lines_of(const TriggerConfig& c) { return {c.gpio_lines[0], c.gpio_lines[1], c.gpio_lines[2]}; }

bool wants(const TriggerConfig& c, const char* input) {
  return std::find(c.inputs.begin(), c.inputs.end(), input) != c.inputs.end();
}

}  // namespace

std::unique_ptr<TriggerInput> make_gpio_input(std::unique_ptr<drivers::GpioEventSource> events,
                                              const TriggerConfig& config, std::string name) {
  const auto debounce_ns = static_cast<std::int64_t>(std::llround(config.gpio_debounce_ms * 1e6));
  return std::make_unique<GpioInput>(drivers::GpioTriggerInput(std::move(events), lines_of(config), debounce_ns),
                                     std::move(name));
}

std::unique_ptr<TriggerInput> make_can_input_on_socket(int fd, const TriggerConfig& config, std::string name) {
  return std::make_unique<CanInput>(drivers::CanTriggerInput::from_socket(fd, config.can_id), std::move(name));
}

std::vector<std::unique_ptr<TriggerInput>> open_trigger_inputs(const TriggerConfig& config) {
  std::vector<std::unique_ptr<TriggerInput>> out;
  if (wants(config, "gpio"))
    out.push_back(make_gpio_input(drivers::open_gpio_lines(config.gpio_chip, lines_of(config)), config,
                                  "gpio " + config.gpio_chip));
  if (wants(config, "can"))
    out.push_back(std::make_unique<CanInput>(drivers::CanTriggerInput(config.can_interface, config.can_id),
                                             "can " + config.can_interface));
  return out;
}

}  // namespace eical::daemon
