#pragma once
// eical-result/1 (docs/result-format.md): JSON objects for each evaluation. Keys are
// fixed by the spec; extra keys are allowed and used for figures the spec does not name.
// A figure that could not be determined is null with a reason in quality.flags.
#include "dsp/analysis/analyze_run.hpp"
#include "dsp/core/run.hpp"
#include "dsp/eval/circle.hpp"
#include "dsp/eval/circle_diagnostics.hpp"
#include "dsp/eval/path_deviation.hpp"
#include "dsp/eval/positioning.hpp"
#include "dsp/eval/rectangle.hpp"
#include "dsp/eval/step_response.hpp"

#include <nlohmann/json.hpp>

#include <filesystem>
#include <string>

namespace eical::drivers {

// The whole eical-result/1 document of an analysed run.
nlohmann::json result_json(const dsp::Run& run, const dsp::Analysis& analysis);

nlohmann::json circle_json(const dsp::Program& program, const dsp::eval::CircleResult& c);
// The positioning object of results.md; deviation_um.up/down are [run][target].
nlohmann::json positioning_json(const dsp::eval::PositioningInput& in, const dsp::eval::PositioningResult& r,
                                bool vdi3441);
nlohmann::json diagnostics_json(const dsp::eval::CircleDiagnostics& d);
nlohmann::json step_json(const std::string& axis, const dsp::eval::StepResult& r);
nlohmann::json rectangle_json(const dsp::eval::RectangleResult& r);
// Free-form deviation along the path (also the rectangle's contour between the corners).
nlohmann::json path_json(const dsp::eval::PathDeviation& d);

// Writes the document to `file` atomically (temporary + rename).
void write_result(const dsp::Run& run, const dsp::Analysis& analysis, const std::filesystem::path& file);

// uncertainty_k2: every figure's expanded uncertainty by result key (arrays keep their
// figure's shape); null where it could not be estimated.
nlohmann::json uncertainty_json(const dsp::Analysis& analysis);

// A finite number, or null (callers add the reason to quality.flags).
nlohmann::json number_or_null(double v);

}  // namespace eical::drivers
