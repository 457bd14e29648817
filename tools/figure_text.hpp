#pragma once
// Figures as a person reads them: "circular deviation G   2.80 ± 1.10 µm", "not resolved"
// when a figure is not above its uncertainty (dsp/uncertainty/resolved.hpp). The label and
// unit of a key: dsp::label_of_key, dsp::unit_of_key (dsp/core/key_unit.hpp).
#include "dsp/analysis/analyze_run.hpp"
#include "dsp/analysis/figures.hpp"

#include <optional>
#include <string>

namespace eical::tools {

// "2.80 ± 1.10 µm", or "2.80 µm ± ?" without an uncertainty; decimals by the unit.
std::string value_with_u(double value, std::optional<double> u_k2, const std::string& unit);

// The sensor model the pipeline compensated with, as a reader names it: "the data sheet's
// sensor model", or "the sensor calibration (method psd)" (AnalysisOptions::sensor_model).
std::string sensor_model_text(const dsp::Analysis& a);

// U of element `i` of a figure, when estimated.
std::optional<double> figure_u(const dsp::Analysis& a, const std::string& key, std::size_t i = 0);

}  // namespace eical::tools
