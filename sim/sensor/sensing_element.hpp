#pragma once
// What happens inside one triplex accelerometer before its output reaches the DAQ:
// the PT2 dynamics of each sensing element (6-3), with damping that may grow with the
// acceleration amplitude (squeeze-film damping, ch. 8.3.1), then the fast part of the
// static model (6-4): a + k2 a² + k3 a³ + cross-axis terms. The slow terms of (6-4) — bias,
// its drift and the temperature dependence of k1 and bias — and the white noise are added
// by the simulator at the DAQ rate (they are constant over the DAQ filter's length).
#include "sim/scenario.hpp"

#include <array>
#include <vector>

namespace eical::sim {

// In place: specific force along the sensor axes (g) on the internal grid → the sensing
// elements' output (g), before k1 and bias. `step_s` is the internal sampling step.
void sense(std::array<std::vector<double>, 3>& axes_g, const SensorTruth& sensor, double step_s);

}  // namespace eical::sim
