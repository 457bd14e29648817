#pragma once
// Helpers for the pipeline's end-to-end tests: run a configured pipeline over a simulated
// run and compare with the simulator's true relative position.
#include "dsp/pipeline/pipeline.hpp"
#include "sim/simulate.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

namespace eical::testutil {

inline sim::Scenario ideal_adc(sim::Scenario sc) {
  sc.noise = false;
  sc.meta.acquisition.adc_bits = 32;
  sc.meta.acquisition.adc_lsb_volt = 1e-9;  // quantisation far below the figures checked
  return sc;
}

struct SimRun {
  dsp::Run run;
  std::vector<Eigen::Vector3d> true_mm;
};

inline SimRun simulate_with_truth(const sim::Scenario& sc) {
  SimRun r;
  r.run = sim::simulate(sc, &r.true_mm);
  return r;
}

inline dsp::PipelineConfig config_for(const dsp::Run& run) { return dsp::pipeline_config(run.meta, run.frames.size()); }

inline dsp::Measurement run_pipeline(const dsp::Run& run, const dsp::PipelineConfig& cfg) {
  dsp::Pipeline p(cfg);
  for (const auto& f : run.frames) p.step(f);
  return p.finish();
}

// Largest |measured − true| over the trace along `axis` (−1: Euclidean), µm.
inline double max_error_um(const dsp::Measurement& m, const std::vector<Eigen::Vector3d>& true_mm, int axis = -1) {
  double worst = 0.0;
  for (std::size_t i = 0; i < m.pos_mm.size(); ++i) {
    const Eigen::Vector3d e = m.pos_mm[i] - true_mm[static_cast<std::size_t>(m.sample_index[i])];
    worst = std::max(worst, axis < 0 ? e.norm() : std::abs(e[axis]));
  }
  return worst * 1000.0;
}

// Largest |a − b| between two traces of the same run, µm.
inline double max_difference_um(const dsp::Measurement& a, const dsp::Measurement& b) {
  double worst = 0.0;
  for (std::size_t i = 0; i < std::min(a.pos_mm.size(), b.pos_mm.size()); ++i)
    worst = std::max(worst, (a.pos_mm[i] - b.pos_mm[i]).cwiseAbs().maxCoeff());
  return worst * 1000.0;
}

}  // namespace eical::testutil
