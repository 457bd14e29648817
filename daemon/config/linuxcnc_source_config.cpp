#include "daemon/config/linuxcnc_source_config.hpp"

#include "drivers/source/sim_factory.hpp"

#include <cmath>

namespace eical::daemon {

std::unique_ptr<drivers::Source> make_linuxcnc_source(const DaemonConfig& config) {
  const LinuxcncConfig& l = config.source.linuxcnc;
  drivers::SimMachine m;
  m.builtin = dsp::ProgramKind::freeform;
  m.program = *l.program_loaded;
  m.seed = l.seed;
  m.meta = hardware_meta(config);
  m.scenario_file = l.scenario_file;
  drivers::LinuxcncSourceOptions o;
  o.fifo = l.fifo;
  o.window.servo_rate_hz = l.servo_rate_hz;
  o.window.block_cycles = static_cast<std::size_t>(std::lround(l.block_ms * 1e-3 * l.servo_rate_hz));
  o.window.history_cycles = static_cast<std::size_t>(std::lround(l.history_ms * 1e-3 * l.servo_rate_hz));
  o.drive_from_feedback = l.drive == "feedback";
  o.connect_timeout_s = l.connect_timeout_s;
  o.stall_timeout_s = l.stall_timeout_s;
  o.hold_s = l.hold_ms * 1e-3;
  return drivers::make_linuxcnc_sim_source(m, o);
}

}  // namespace eical::daemon
