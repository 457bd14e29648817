#pragma once
// A strip's readings while the spot runs along it give the position and, through their
// slope, the velocity. The integrated path's slope is known only to the sensors' scale
// (ErrorModel::scale_uncertainty): where the scale's share across a crossing exceeds what
// the readings resolve of the slope, the slope is the scale error, not the bias. Taken as
// independent fixes, the readings pinned the velocity to it, and the smoother carried
// scale × v (24 µm/s at 50 mm/s and 5e-4) into the next standstill, whose ZUPTs then
// rejected it: resets, and a data-sheet positioning run lost its strip (psd_disagrees) and
// integrated its targets apart by a random walk instead. Such a crossing becomes one fix:
// the readings' mean innovation at its middle sample.
#include "dsp/fusion/error_model.hpp"
#include "dsp/fusion/support_schedule.hpp"

#include <array>
#include <cstddef>
#include <vector>

namespace eical::dsp::fusion {

// Readings of one strip further apart than this are two crossings (a lost frame is not).
inline constexpr double kCrossingGapS = 0.002;

// `fixes` in ascending k, `fix_pos_mm` the integrated position at each (same order);
// readings of one strip more than `max_gap_samples` apart are separate crossings. Both
// vectors are rewritten, still in ascending k. `scale_state_ppm` (ErrorModel's): on an axis
// where the filter keeps the scale as a state, a merged fix adds no scale share between
// crossings to its σ (the state carries it).
void merge_crossings(std::vector<PositionFix>& fixes, std::vector<double>& fix_pos_mm, double scale_uncertainty,
                     std::size_t max_gap_samples, const std::array<double, 3>& scale_state_ppm = {});

}  // namespace eical::dsp::fusion
