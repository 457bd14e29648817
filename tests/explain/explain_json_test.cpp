// eical-explain/1 (docs/result-format.md): the keys of the document and of every effect,
// effect names from run-format.md's table (or other.<name>), the reference named, and two
// runs of one machine giving the held-out-across-runs block.
#include "dsp/model/effects.hpp"
#include "dsp/model/explain.hpp"
#include "sim/hidden/hidden_effects.hpp"
#include "sim/simulate.hpp"
#include "tools/explain/explain_outputs.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

namespace eical {
namespace {

TEST(ExplainJson, KeysOfResultsMdAndNamesOfTheEffectTable) {
  std::vector<dsp::Run> runs = {
      sim::simulate(sim::hidden_effect_scenario({"sensor.scale"}, eical::dsp::ProgramKind::step, 102)),
      sim::simulate(sim::hidden_effect_scenario({"sensor.scale"}, eical::dsp::ProgramKind::circle, 102))};
  std::vector<dsp::model::RunExplanation> ex;
  for (const auto& r : runs) ex.push_back(dsp::model::explain_run(r));
  std::vector<dsp::model::TransferGain> transfers = {dsp::model::transfer_gain(runs[1], ex[0])};
  const nlohmann::json j = tools::explain::explain_json(runs, ex, transfers);

  EXPECT_EQ(j.at("format"), "eical-explain/1");
  ASSERT_EQ(j.at("runs").size(), 2u);
  EXPECT_EQ(j.at("reference"), "ref");  // both runs carry a reference encoder
  for (const char* k : {"nominal_residual_rms_um", "final_residual_rms_um", "heldout_nominal_residual_rms_um",
                        "heldout_final_residual_rms_um", "runtime_s_per_run"})
    EXPECT_TRUE(j.at(k).is_number()) << k;
  std::vector<std::string_view> names;
  for (const auto& i : dsp::model::effect_catalogue()) names.push_back(i.name);
  ASSERT_GE(j.at("effects").size(), 10u);  // every effect tested is listed, significant or not
  bool seen_insignificant = false;
  for (const auto& e : j.at("effects")) {
    const std::string name = e.at("name");
    EXPECT_TRUE(std::find(names.begin(), names.end(), std::string_view(name)) != names.end() ||
                name.rfind("other.", 0) == 0)
        << name;
    EXPECT_TRUE(e.at("significant").is_boolean());
    EXPECT_TRUE(e.at("evidence").is_string() && !e.at("evidence").get<std::string>().empty()) << name;
    EXPECT_TRUE(e.at("params").is_object());
    for (const char* k :
         {"residual_rms_before_um", "residual_rms_after_um", "heldout_rms_before_um", "heldout_rms_after_um"})
      EXPECT_TRUE(e.at(k).is_number()) << name << "." << k;
    if (!e.at("significant")) seen_insignificant = true;
    // Significant ones come first.
    if (e.at("significant")) {
      EXPECT_FALSE(seen_insignificant) << name << " significant after an insignificant one";
    }
  }
  EXPECT_EQ(j.at("effects").front().at("name"), "sensor.scale");
  ASSERT_EQ(j.at("heldout_runs").size(), 1u);
  const auto& h = j.at("heldout_runs").front();
  EXPECT_EQ(h.at("model_from"), runs[0].meta.id);
  EXPECT_EQ(h.at("applied_to"), runs[1].meta.id);
  EXPECT_TRUE(h.at("residual_rms_before_um").is_number() && h.at("residual_rms_after_um").is_number());
  ASSERT_EQ(j.at("per_run").size(), 2u);
  // Show: the step run's residual against the regressors; a scale error follows the position.
  const auto& corr = j.at("per_run").front().at("correlations");
  ASSERT_GE(corr.size(), 10u);
  double r_position = 0.0;
  for (const auto& c : corr) {
    EXPECT_TRUE(c.at("r").is_number());
    EXPECT_LE(std::abs(c.at("r").get<double>()), 1.0 + 1e-9);
    if (c.at("axis") == "x" && c.at("regressor") == "position") r_position = c.at("r");
  }
  EXPECT_GT(std::abs(r_position), 0.5);
}

}  // namespace
}  // namespace eical
