#pragma once
// A parsed NC program: modal state resolved, every move in absolute millimetres.
// The interpolator (sim/nc) turns these blocks into a set-point trajectory.
#include <Eigen/Core>

#include <string>
#include <variant>
#include <vector>

namespace eical::sim::gcode {

enum class Plane { xy, zx, yz };  // G17, G18, G19 (arcs turn about Z, Y, X)

struct Linear {
  Eigen::Vector3d from_mm;
  Eigen::Vector3d to_mm;
  double feed_mm_min;  // G1 feed; for G0 the machine's rapid rate is used instead
  bool rapid;          // G0
};

struct Arc {
  Eigen::Vector3d from_mm;
  Eigen::Vector3d to_mm;
  Eigen::Vector3d center_mm;  // centre in the arc plane; the helical axis keeps `from`'s value
  Plane plane;
  bool clockwise;    // G2 (viewed from the positive axis normal to the plane)
  double sweep_rad;  // signed: positive counter-clockwise; |sweep| in (0, 2π]
  double feed_mm_min;
};

struct Dwell {
  double duration_s;  // G4 P<seconds> (LinuxCNC convention)
};

// M-function raised to the measurement system (M101 start, M102 segment, M103 end, ...).
struct Trigger {
  int code;
  double p;  // P word (NaN when absent)
  double q;  // Q word (NaN when absent)
};

using Block = std::variant<Linear, Arc, Dwell, Trigger>;

struct SourceRef {
  int line;  // 1-based line in the G-code text
};

struct Program {
  std::vector<Block> blocks;
  std::vector<SourceRef> source;  // same size as blocks
  bool exact_stop = true;         // G61 (true) or G64 continuous path (false), last one set
};

}  // namespace eical::sim::gcode
