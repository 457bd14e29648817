#pragma once
// The figures of the same evaluation on another path: a measured analysis's program, its
// marks and set-point, evaluated on a path given per frame (the simulator's true relative
// path). What the measured figures are compared with (the demo, `eical plan --check`, the
// uncertainty campaign); the diagnostics keep the measured run's cyclic pitch so that both
// evaluations look at the same period.
#include "dsp/analysis/analyze_run.hpp"
#include "dsp/analysis/figures.hpp"

#include <Eigen/Core>

#include <vector>

namespace eical::dsp {

// path_mm: one position per frame of `run`, from its first frame; frames beyond it keep the
// measured position.
std::vector<FigureValue> figures_on_path(const Run& run, const std::vector<Eigen::Vector3d>& path_mm,
                                         const Analysis& measured);

}  // namespace eical::dsp
