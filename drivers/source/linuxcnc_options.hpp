#pragma once
// How the `linuxcnc` source follows LinuxCNC's servo stream and simulates the sensors in
// windows of it (linuxcnc_source.hpp, windowed_sim.hpp), without the simulator's types:
// eicald sets these from [source.linuxcnc].
#include <cstddef>
#include <filesystem>

namespace eical::drivers {

struct WindowedSimOptions {
  double servo_rate_hz = 1000.0;
  std::size_t block_cycles = 200;
  std::size_t history_cycles = 300;
  std::size_t lookahead_cycles = 5;
  std::size_t prefix_cycles = 60;  // 10 hold, 20 approach, 30 settle (DAQ filter, PT2)
};

struct LinuxcncSourceOptions {
  std::filesystem::path fifo = "/run/eical/linuxcnc-servo.fifo";
  WindowedSimOptions window;
  bool drive_from_feedback = false;    // feedback (LinuxCNC's plant) instead of the command drives the machine
  double connect_timeout_s = 10.0;     // open(): first servo line within this time, else "LinuxCNC absent"
  double stall_timeout_s = 2.0;        // no line for this long while streaming: the source fails
  double hold_s = 1.0;                 // frames are released this long after their servo cycle (DDS trigger latency)
  std::size_t max_fill_cycles = 1000;  // lost cycles up to this many are interpolated; more fail the source
  std::size_t ring_frames = 1u << 16;
};

}  // namespace eical::drivers
