#pragma once
// The white noise a run measured at rest (dsp/pipeline/rest_noise.hpp) against the data
// sheet's: the uncertainty's draws use the measured density, and say where it came from;
// a density outside the data sheet's spread (beyond the measurement's own uncertainty) is
// flagged — a sensor or a DAQ channel that is noisier than specified, or vibration that
// does not cancel between head and table.
#include "dsp/core/flag.hpp"
#include "dsp/core/run_meta.hpp"
#include "dsp/core/sensor_model_covariance.hpp"
#include "dsp/pipeline/rest_noise.hpp"

#include <optional>
#include <string>

namespace eical::dsp::uncertainty {

// head − table's density by the data sheet (two-sided, µg/√Hz): √(n_table² + n_head²).
double datasheet_relative_noise(const SensorSpec sensors[2]);

// The noise_density flag when the measured density disagrees with the data sheet's.
std::optional<Flag> noise_disagreement(const RestNoise& measured, double datasheet_ug_rthz,
                                       const DatasheetTolerance& tolerance = {});

// Where the draws' noise came from, for the uncertainty's note.
std::string noise_source_text(const RestNoise& measured, double datasheet_ug_rthz);

}  // namespace eical::dsp::uncertainty
