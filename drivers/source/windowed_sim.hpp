#pragma once
// Turns a stream of servo-rate positions (another NC's set-point) into DAQ frames through
// eical's full simulator, block by block. sim::simulate is a batch computation, so each
// block is simulated in a window:
//   [prefix | history | block | lookahead]
// * prefix: a short approach to the window's first position in the direction each axis
//   last moved, so the backlash play is taken up on the right side (the one machine state
//   that outlives any history), then a rest so the first block of a stream starts settled;
// * history: long enough for the position loops, sensor, DAQ filter and PSD lock-in to
//   forget the window's start (checked against the scenario's Kv);
// * lookahead: keeps the spline's free end out of the block.
// Only the block's frames are emitted. Each window draws fresh noise (seed + block
// number). Effects whose state or clock outlives the history — bias random walk, bias
// steps and drift, warming case temperature, stick-slip, vibration modes and tones — are
// refused with a message naming them.
#include "drivers/source/linuxcnc_options.hpp"
#include "dsp/core/frame.hpp"
#include "sim/scenario.hpp"

#include <Eigen/Core>

#include <cstdint>
#include <span>
#include <vector>

namespace eical::drivers {

class WindowedSim {
 public:
  // Throws SourceError when fs is not a whole multiple of the servo rate or the scenario
  // has an effect the windows cannot continue.
  WindowedSim(sim::Scenario scenario, WindowedSimOptions options);

  // One servo cycle: the position that drives the simulated machine (mm), the commanded
  // position the frames carry as set-point, and whether the cycle was filled in for a lost
  // one (its frames are flagged cmd_missing). Between cycles the frames' set-point is
  // interpolated linearly, so at rest it is bit-for-bit constant (the pipeline detects
  // motion by any change of the set-point).
  void push(const Eigen::Vector3d& drive_mm, const Eigen::Vector3d& cmd_mm, bool filled = false);
  void push(const Eigen::Vector3d& pos_mm, bool filled = false) { push(pos_mm, pos_mm, filled); }
  [[nodiscard]] bool block_ready() const { return pending_ >= options_.block_cycles + options_.lookahead_cycles; }
  // Frames one block yields (block_cycles · fs / servo rate).
  [[nodiscard]] std::size_t frames_per_block() const { return options_.block_cycles * ratio_; }
  // Simulates the pending block (or, with `flush`, everything pushed so far) into `out`
  // (at least frames_per_block(), or pending cycles · ratio with flush); returns the count.
  // Frames carry consecutive sample indices from 0; frame n is servo cycle n / ratio.
  std::size_t simulate_block(std::span<dsp::Frame> out, bool flush = false);
  [[nodiscard]] int ratio() const { return ratio_; }
  [[nodiscard]] const sim::Scenario& scenario() const { return scenario_; }
  [[nodiscard]] std::uint64_t blocks() const { return blocks_; }

 private:
  sim::Scenario scenario_;
  WindowedSimOptions options_;
  int ratio_ = 10;                     // DAQ frames per servo cycle
  std::vector<Eigen::Vector3d> hist_;  // history + pending cycles (drive positions)
  std::vector<Eigen::Vector3d> cmd_;   // the commanded positions of the same cycles
  std::vector<char> filled_;           // per entry of hist_
  std::size_t pending_ = 0;            // cycles of hist_ not yet emitted
  std::int64_t emitted_cycles_ = 0;    // servo cycles whose frames went out
  int dir_[3] = {1, 1, 1};             // last direction of each axis before hist_[0]
  std::uint64_t blocks_ = 0;
  std::vector<Eigen::Vector3d> window_;  // reused window positions
};

}  // namespace eical::drivers
