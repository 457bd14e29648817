#pragma once
// What `eical explain` writes: the eical-explain/1 document (docs/result-format.md),
// the summary text, and the report folder — HTML with the residuals before and after the
// accepted extensions in time and frequency, the sensor calibration the accepted sensor
// effects make (eical-sensor-cal/1, method "explain") and a scenario (eical-scenario/1)
// with which the simulator reproduces the run.
#include "dsp/core/run.hpp"
#include "dsp/model/explain.hpp"

#include <nlohmann/json.hpp>

#include <filesystem>
#include <string>
#include <vector>

namespace eical::tools::explain {

// `transfers`: each run's extension applied to the other runs (held out across runs).
nlohmann::json explain_json(const std::vector<dsp::Run>& runs, const std::vector<dsp::model::RunExplanation>& ex,
                            const std::vector<dsp::model::TransferGain>& transfers = {});
std::string explain_text(const std::vector<dsp::model::RunExplanation>& ex,
                         const std::vector<dsp::model::TransferGain>& transfers = {});
void write_explain_report(const std::vector<dsp::Run>& runs, const std::vector<dsp::model::RunExplanation>& ex,
                          const std::filesystem::path& dir);

}  // namespace eical::tools::explain
