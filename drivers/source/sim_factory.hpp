#pragma once
// The daemon's one way to the simulated machine, its backend when no hardware is present
// ([source.sim]): what to simulate is said in the run format's terms (dsp::RunMeta,
// dsp::Program), so that eicald never includes the simulator.
#include "drivers/source/linuxcnc_options.hpp"
#include "drivers/source/replay_source.hpp"
#include "dsp/core/run_meta.hpp"

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>

namespace eical::drivers {

struct SimMachine {
  // The program the simulated NC runs: a `program` file's, or the built-in one named by
  // `builtin` ("circle": R radius_mm at feed, repeats revolutions, ccw; "step": 0 → 50 mm
  // along x, repeats runs; "freeform": none, LinuxCNC's servo stream moves the machine).
  std::optional<dsp::Program> program;
  dsp::ProgramKind builtin = dsp::ProgramKind::circle;
  double radius_mm = 10.0, feed_mm_min = 2500.0;
  int repeats = 5;
  std::uint64_t seed = 1;
  // What the service believes about its hardware: the DAQ, site, machine and envelope the
  // simulation runs with. Without `scenario_file` the machine is ideal and carries exactly
  // these sensors (as true sensors too) and strips; with it, the file's machine errors and
  // sensor truth stand (eical simulate's scenario format).
  dsp::RunMeta meta;
  std::filesystem::path scenario_file;
};

struct SimPacing {
  Pacing pacing = Pacing::realtime;
  bool repeat = false;  // run the program again after idle_s of rest
  double idle_s = 2.0;
};

std::unique_ptr<Source> make_sim_source(const SimMachine& machine, const SimPacing& pacing);

// The simulated sensors moved by LinuxCNC's servo stream (the `linuxcnc` source).
std::unique_ptr<Source> make_linuxcnc_sim_source(const SimMachine& machine, const LinuxcncSourceOptions& options);

// Where the simulated NC's program leaves the machine's envelope: the envelope key it
// breaks and the excursion in words; nullopt when it stays within (or no envelope is set).
struct EnvelopeBreach {
  std::string key, text;
};
std::optional<EnvelopeBreach> sim_program_outside_envelope(const SimMachine& machine);

}  // namespace eical::drivers
