#include "daemon/config/linuxcnc_source_config.hpp"

#include "drivers/config/scenario_file.hpp"
#include "drivers/source/linuxcnc_source.hpp"

#include <cmath>

namespace eical::daemon {

std::unique_ptr<drivers::Source> make_linuxcnc_source(const DaemonConfig& config) {
  const LinuxcncConfig& l = config.source.linuxcnc;
  sim::Scenario sc = l.scenario_file.empty() ? sim::gcode_scenario("", "freeform", l.seed)
                                             : drivers::read_scenario_file(l.scenario_file.string());
  const bool truth_from_file = !l.scenario_file.empty();
  sc.seed = l.seed;
  sc.meta.program = *l.program_loaded;
  sc.meta.acquisition = config.acquisition;
  sc.meta.site = config.site;
  sc.meta.machine = config.machine;
  sc.meta.envelope = config.envelope;
  sc.meta.sensors[0] = config.sensors[0];
  sc.meta.sensors[1] = config.sensors[1];
  // Without a scenario file the sensors are exactly what the configuration says.
  if (!truth_from_file)
    for (int s = 0; s < 2; ++s) sc.truth[s].spec = config.sensors[s];
  drivers::LinuxcncSourceOptions o;
  o.fifo = l.fifo;
  o.window.servo_rate_hz = l.servo_rate_hz;
  o.window.block_cycles = static_cast<std::size_t>(std::lround(l.block_ms * 1e-3 * l.servo_rate_hz));
  o.window.history_cycles = static_cast<std::size_t>(std::lround(l.history_ms * 1e-3 * l.servo_rate_hz));
  o.drive_from_feedback = l.drive == "feedback";
  o.connect_timeout_s = l.connect_timeout_s;
  o.stall_timeout_s = l.stall_timeout_s;
  o.hold_s = l.hold_ms * 1e-3;
  return std::make_unique<drivers::LinuxcncSource>(std::move(sc), o);
}

}  // namespace eical::daemon
