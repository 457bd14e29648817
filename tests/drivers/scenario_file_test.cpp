// Scenario files: every effect of the run format switched on from a file, strict errors.
#include "drivers/config/scenario_file.hpp"
#include "dsp/core/error.hpp"
#include "sim/effects.hpp"
#include "sim/simulate.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

namespace eical {
namespace {

std::string write_tmp(const std::string& name, const std::string& text) {
  const auto p = std::filesystem::temp_directory_path() / name;
  std::ofstream(p) << text;
  return p.string();
}

TEST(ScenarioFile, EveryEffectOfTheRunFormatCanBeSwitchedOn) {
  const sim::Scenario sc = drivers::read_scenario_file(EICAL_SOURCE_DIR "/config/scenarios/everything.toml");
  const sim::EffectLists l = sim::effect_lists(sc);
  std::vector<std::string> all = l.present;
  all.insert(all.end(), l.background.begin(), l.background.end());
  for (const auto& name : sim::effect_names()) EXPECT_NE(std::find(all.begin(), all.end(), name), all.end()) << name;
  EXPECT_NE(std::find(l.background.begin(), l.background.end(), "site.coriolis"), l.background.end());
  EXPECT_EQ(sc.meta.psd.size(), 2u);
  const dsp::Run run = sim::simulate(sc);
  ASSERT_TRUE(run.truth_toml.has_value());
  for (const auto& name : l.present)
    EXPECT_NE(run.truth_toml->find("[effects.\"" + name + "\"]"), std::string::npos) << name;
  EXPECT_EQ(run.channels.psd_count, 2);
  // Both strips are crossed by the R10 circle: light reaches each at some time.
  for (int c = 0; c < 4; ++c) {
    std::int32_t peak = 0;
    for (const auto& f : run.frames) peak = std::max(peak, f.psd_counts[c]);
    EXPECT_GT(peak, 100000) << "psd channel " << c;
  }
}

TEST(ScenarioFile, BacklashExampleMatchesItsTruth) {
  const sim::Scenario sc = drivers::read_scenario_file(EICAL_SOURCE_DIR "/config/scenarios/backlash-circle.toml");
  EXPECT_DOUBLE_EQ(sc.machine.backlash_um[0], 4.0);
  EXPECT_DOUBLE_EQ(sc.machine.spike[1].amp_um, 2.0);
  EXPECT_EQ(sim::effect_lists(sc).present, (std::vector<std::string>{"machine.backlash", "machine.reversal_spike"}));
}

TEST(ScenarioFile, AnEffectOnSeveralAxesIsAnArrayOfTables) {
  const std::string text =
      "format = \"eical-scenario/1\"\n[program]\nkind = \"circle\"\nradius_mm = 10.0\n"
      "[[effects.\"machine.backlash\"]]\naxis = \"x\"\nvalue_um = 3\n"
      "[[effects.\"machine.backlash\"]]\naxis = \"y\"\nvalue_um = 1.5\n";
  const sim::Scenario sc = drivers::read_scenario_file(write_tmp("eical-scenario-axes.toml", text));
  EXPECT_DOUBLE_EQ(sc.machine.backlash_um[0], 3.0);
  EXPECT_DOUBLE_EQ(sc.machine.backlash_um[1], 1.5);
  EXPECT_EQ(sim::effect_lists(sc).present, (std::vector<std::string>{"machine.backlash"}));
}

// One machine's scenario runs several programs; the history keeps runs by id, so the
// default id names the program too (a stated id is kept as it is).
TEST(ScenarioFile, TheDefaultRunIdNamesTheProgram) {
  const std::string head = "format = \"eical-scenario/1\"\nname = \"dmu50\"\nseed = 7\n";
  const sim::Scenario circle = drivers::read_scenario_file(
      write_tmp("eical-scenario-id-circle.toml", head + "[program]\nkind = \"circle\"\nradius_mm = 10.0\n"));
  const sim::Scenario positioning = drivers::read_scenario_file(
      write_tmp("eical-scenario-id-positioning.toml", head + "[program]\nkind = \"positioning\"\naxis = \"x\"\n"
                                                             "targets_mm = [0.0, 10.0]\n"));
  EXPECT_EQ(circle.meta.id, "sim-dmu50-circle-s7");
  EXPECT_EQ(positioning.meta.id, "sim-dmu50-positioning-s7");
  const sim::Scenario stated =
      drivers::read_scenario_file(write_tmp("eical-scenario-id-stated.toml",
                                            "format = \"eical-scenario/1\"\nid = \"acceptance-7\"\n[program]\n"
                                            "kind = \"circle\"\nradius_mm = 10.0\n"));
  EXPECT_EQ(stated.meta.id, "acceptance-7");
}

TEST(ScenarioFile, UnknownEffectKeyAndTypeAreNamedWithTheLine) {
  const std::string head = "format = \"eical-scenario/1\"\n[program]\nkind = \"circle\"\nradius_mm = 10.0\n";
  auto error_of = [&](const std::string& body) {
    try {
      drivers::read_scenario_file(write_tmp("eical-scenario-test.toml", head + body));
    } catch (const dsp::InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(error_of("[effects.\"machine.backlsh\"]\naxis = \"x\"\nvalue_um = 3\n").find(":5:"), std::string::npos);
  EXPECT_NE(error_of("[effects.\"machine.backlsh\"]\naxis = \"x\"\nvalue_um = 3\n").find("unknown effect"),
            std::string::npos);
  // A misspelt required key is reported missing; a misspelt optional one as unknown, with its line.
  EXPECT_NE(
      error_of("[effects.\"machine.backlash\"]\naxis = \"x\"\nvalu_um = 3\n").find("value_um: required key is missing"),
      std::string::npos);
  EXPECT_NE(error_of("[effects.\"machine.reversal_spike\"]\naxis = \"x\"\namp_um = 3\ntau_mss = 9\n")
                .find(":8: effects.machine.reversal_spike.tau_mss: unknown key"),
            std::string::npos)
      << error_of("[effects.\"machine.reversal_spike\"]\naxis = \"x\"\namp_um = 3\ntau_mss = 9\n");
  EXPECT_NE(error_of("[effects.\"machine.backlash\"]\naxis = \"w\"\nvalue_um = 3\n").find("axis"), std::string::npos);
  EXPECT_NE(error_of("[effects.\"sensor.dynamics\"]\nf0_hz = -5\n").find("f0_hz: must be positive"), std::string::npos);
  EXPECT_NE(
      error_of("[effects.\"machine.straightness\"]\naxis = \"x\"\ndirection = \"x\"\nbow_um = 1\n").find("direction"),
      std::string::npos);
  EXPECT_EQ(error_of(""), "no error");
}

}  // namespace
}  // namespace eical
