#pragma once
// The machine's work envelope: how far each axis travels, how fast and how hard the machine
// may move. A program beyond it is refused before anything is simulated or written
// (eical gen-nc, simulate, plan), so that a typo such as --radius 100000 is an error
// naming the limit, not an hour of simulation or an exhausted memory.
//
// Travel is in the program's coordinates (where eical's programs are centred: the circle's
// centre, the step's start), the same as cmd_*/ref_* of a run. The defaults are a mid-size
// vertical machining centre, 1000 x 600 x 600 mm of travel, with the program's origin at
// its middle, 30 m/min rapid and 1 g: larger than every program of the examples and tests
// (R150 circles in any plane, 200 mm steps), smaller than any typo worth catching.
//
// Set in eicald.toml and run.toml as [envelope] (drivers/config/meta_sections.hpp), on the
// command line as --travel-x/-y/-z, --max-feed, --max-accel or --envelope FILE.
namespace eical::dsp {

struct WorkEnvelope {
  // x, y, z: min, max.
  double travel_mm[3][2] = {{-500.0, 500.0}, {-300.0, 300.0}, {-300.0, 300.0}};
  // Path speed, rapid moves included.
  double max_feed_mm_min = 30000.0;
  // Path acceleration, centripetal included (1 g).
  double max_accel_mm_s2 = 9810.0;
};

}  // namespace eical::dsp
