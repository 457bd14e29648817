#include "drivers/source/sim_factory.hpp"

#include "drivers/config/scenario_file.hpp"
#include "drivers/source/linuxcnc_source.hpp"
#include "drivers/source/sim_source.hpp"
#include "sim/nc/envelope_check.hpp"
#include "sim/scenario.hpp"
#include "sim/simulate.hpp"

namespace eical::drivers {
namespace {

sim::Scenario builtin_scenario(const SimMachine& m) {
  switch (m.builtin) {
    case dsp::ProgramKind::circle: return sim::circle_scenario(m.radius_mm, m.feed_mm_min, m.repeats, "ccw", m.seed);
    case dsp::ProgramKind::step: return sim::step_scenario(0.0, 50.0, m.feed_mm_min, m.repeats, m.seed);
    case dsp::ProgramKind::positioning:
    case dsp::ProgramKind::rectangle:
    case dsp::ProgramKind::freeform:
    case dsp::ProgramKind::identify:
      break;  // none built in: a program file's, or LinuxCNC's servo stream moves the machine
  }
  return sim::gcode_scenario("", dsp::ProgramKind::freeform, m.seed);
}

sim::Scenario scenario_of(const SimMachine& m) {
  const bool ideal = m.scenario_file.empty();
  sim::Scenario sc = ideal ? builtin_scenario(m) : read_scenario_file(m.scenario_file.string());
  sc.seed = m.seed;
  if (m.program) sc.meta.program = *m.program;
  sc.meta.acquisition = m.meta.acquisition;
  sc.meta.site = m.meta.site;
  sc.meta.machine = m.meta.machine;
  sc.meta.envelope = m.meta.envelope;
  for (int s = 0; s < 2; ++s) sc.meta.sensors[s] = m.meta.sensors[s];
  if (ideal) {
    sc.meta.psd = m.meta.psd;  // the strips the simulated machine carries
    for (int s = 0; s < 2; ++s) sc.truth[s].spec = m.meta.sensors[s];
  }
  return sc;
}

}  // namespace

std::unique_ptr<Source> make_sim_source(const SimMachine& machine, const SimPacing& pacing) {
  return std::make_unique<SimSource>(scenario_of(machine),
                                     SimSourceOptions{pacing.pacing, pacing.repeat, pacing.idle_s});
}

std::unique_ptr<Source> make_linuxcnc_sim_source(const SimMachine& machine, const LinuxcncSourceOptions& options) {
  return std::make_unique<LinuxcncSource>(scenario_of(machine), options);
}

std::optional<EnvelopeBreach> sim_program_outside_envelope(const SimMachine& machine) {
  if (!machine.meta.envelope) return std::nullopt;
  const dsp::WorkEnvelope& envelope = *machine.meta.envelope;
  const auto x = sim::nc::envelope_excess(*sim::scenario_set_point(scenario_of(machine)), envelope);
  if (!x) return std::nullopt;
  return EnvelopeBreach{sim::nc::envelope_key(*x), sim::nc::describe(*x, envelope)};
}

}  // namespace eical::drivers
