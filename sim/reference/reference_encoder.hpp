#pragma once
// The reference instrument (a cross-grid encoder such as the KGM182): it reads the true
// relative position with a small scale error and an interpolation error within its
// signal period (first and second harmonic), quantised to its resolution (1 nm).
#include "sim/scenario.hpp"

namespace eical::sim {

// Reading of axis `axis` (0..2) for the true relative position p_mm.
double reference_reading_mm(const ReferenceTruth& ref, int axis, double p_mm) noexcept;

}  // namespace eical::sim
