#pragma once
// The importers' common path after a recording is read: its stamps onto a uniform clock
// and its values resampled there (drivers/import/uniform_clock), as eical import does
// before the cross-correlation; and what an accepted clock must hold.
#include "drivers/import/uniform_clock.hpp"
#include "fuzz/fuzz_support.hpp"

#include <cmath>

namespace eical::fuzz {

// `nc`: an NC trace, whose gaps the importer bridges on the grid (bridge_gaps).
inline void to_uniform_clock(const std::vector<double>& t_s, const std::vector<Eigen::Vector3d>& values,
                             const std::string& source, bool nc = false) {
  const drivers::UniformClock clock = drivers::fit_uniform_clock(t_s, source);
  if (!(clock.fs_hz > 0.0) || !std::isfinite(clock.fs_hz)) finding("a clock whose rate is not positive and finite");
  const drivers::UniformSeries s = drivers::resample(t_s, values, clock);
  if (s.grid_index.size() != t_s.size()) finding("resampling lost or added samples");
  for (std::size_t k = 1; k < s.grid_index.size(); ++k)
    if (s.grid_index[k] <= s.grid_index[k - 1]) finding("grid indices do not increase");
  if (nc && drivers::bridge_gaps(t_s, values, clock).size() != static_cast<std::size_t>(clock.index.back()) + 1)
    finding("the bridged trace does not cover the grid");
}

}  // namespace eical::fuzz
