// Item 4 of issue 7: what explain accepts becomes eical's model. The scenario it writes
// (told: the run's data sheet; truth: the extended sensors) simulates a run that shows
// what the recorded one showed, and the calibration it writes removes the effect from the
// pipeline's result.
#include "tools/explain/extended_model.hpp"
#include "drivers/config/scenario_file.hpp"
#include "drivers/config/sensor_calibration.hpp"
#include "dsp/core/float_limits.hpp"
#include "dsp/model/explain.hpp"
#include "dsp/model/run_residuals.hpp"
#include "sim/hidden/hidden_effects.hpp"
#include "sim/regimes/regimes.hpp"
#include "sim/simulate.hpp"

#include <gtest/gtest.h>

#include <unistd.h>
#include <cmath>
#include <cstdio>
#include <filesystem>

namespace eical {
namespace {

namespace fs = std::filesystem;

double pipeline_rms_um(const dsp::Run& run) {
  const auto rr = dsp::model::build_residuals(run);
  double s = 0.0;
  Eigen::Index n = 0;
  for (Eigen::Index i = 0; i < rr.pipeline.rows(); ++i)
    if (rr.moving[rr.pipeline.axis[static_cast<std::size_t>(i)]])
      s += rr.pipeline.residual_um[i] * rr.pipeline.residual_um[i], ++n;
  return n ? std::sqrt(s / static_cast<double>(n)) : 0.0;
}

TEST(ExtendedModel, ScenarioReproducesTheRunAndTheCalibrationRemovesTheEffect) {
  const dsp::Run run = sim::simulate(sim::hidden_effect_scenario({"sensor.scale"}, eical::dsp::ProgramKind::step, 101));
  const auto ex = dsp::model::explain_run(run);
  const auto model = tools::explain::extended_model(run, ex);
  const fs::path dir = fs::temp_directory_path() / ("eical_ext_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  tools::explain::write_extended_model(model, dir / "cal.toml", dir / "scenario.toml");

  // The scenario, simulated: the nominal pipeline shows the recorded run's residual.
  const dsp::Run resim = sim::simulate(drivers::read_scenario_file((dir / "scenario.toml").string()));
  const double recorded = pipeline_rms_um(run), reproduced = pipeline_rms_um(resim);
  // The calibration, applied: the recorded run's residual falls to what the noise leaves.
  dsp::Run calibrated = run;
  const auto cal = drivers::read_sensor_calibration(dir / "cal.toml", run.meta);
  drivers::apply_calibration(cal, calibrated.meta);
  const double after = pipeline_rms_um(calibrated);
  fs::remove_all(dir);
  std::printf(
      "sensor.scale hidden, step seed 101: pipeline residual recorded %.2f um, reproduced by the scenario %.2f um, "
      "recorded with the calibration %.2f um\n",
      recorded, reproduced, after);
  EXPECT_GT(recorded, 10.0);
  EXPECT_NEAR(reproduced, recorded, 0.2 * recorded);
  EXPECT_LT(after, 0.1 * recorded);
}

// A machine effect on two axes (backlash on x and y of a circle) is written as an array of
// tables the scenario reader takes back, with each axis' value.
TEST(ExtendedModel, AnEffectOnTwoAxesRoundTripsThroughTheScenario) {
  sim::Scenario sc = sim::hidden_effect_scenario({"machine.backlash"}, eical::dsp::ProgramKind::circle, 101);
  sc.machine.backlash_um[0] = 6.0, sc.machine.backlash_um[1] = 4.0;
  const dsp::Run run = sim::simulate(sc);
  const auto ex = dsp::model::explain_run(run);
  const auto model = tools::explain::extended_model(run, ex);
  const fs::path dir = fs::temp_directory_path() / ("eical_ext2_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  tools::explain::write_extended_model(model, dir / "cal.toml", dir / "scenario.toml");
  const sim::Scenario back = drivers::read_scenario_file((dir / "scenario.toml").string());
  fs::remove_all(dir);
  std::printf("backlash x %.2f y %.2f um read back from the written scenario\n", back.machine.backlash_um[0],
              back.machine.backlash_um[1]);
  EXPECT_NEAR(back.machine.backlash_um[0], 6.0, 1.5);
  EXPECT_NEAR(back.machine.backlash_um[1], 4.0, 1.5);
}

// Issue 15 item 5: the extended model carries the modes: the scenario explain writes
// simulates a run in which explain finds them again.
double mode_near(const dsp::model::RunExplanation& ex, double f_hz, double& zeta) {
  for (const auto& e : ex.effects) {
    if (e.name != "machine.resonance" || !e.significant) continue;
    double best = kInf;
    for (int k = 0; e.params.count("mode" + std::to_string(k) + "_frequency_hz"); ++k) {
      const double f = e.params.at("mode" + std::to_string(k) + "_frequency_hz");
      if (std::abs(f - f_hz) < std::abs(best - f_hz))
        best = f, zeta = e.params.at("mode" + std::to_string(k) + "_damping_ratio");
    }
    return best;
  }
  return kInf;
}

TEST(ExtendedModel, TheModesFoundAreSimulatedAgainAndFoundAgain) {
  sim::Scenario sc = sim::hidden_effect_scenario({}, eical::dsp::ProgramKind::step, 101);
  sim::set_sensors_present(sc, "head");
  sim::StructuralMode md;
  md.frequency_hz = 45.0, md.damping_ratio = 0.03, md.gain = 0.15, md.direction = Eigen::Vector3d::UnitX();
  sc.resonance.modes = {md};
  sc.resonance.part = 1;
  const dsp::Run run = sim::simulate(sc);
  const auto ex = dsp::model::explain_run(run);
  const auto model = tools::explain::extended_model(run, ex);
  const fs::path dir = fs::temp_directory_path() / ("eical_ext3_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  tools::explain::write_extended_model(model, dir / "cal.toml", dir / "scenario.toml");
  const sim::Scenario back = drivers::read_scenario_file((dir / "scenario.toml").string());
  fs::remove_all(dir);
  ASSERT_EQ(back.resonance.modes.size(), 1u);
  const auto again = dsp::model::explain_run(sim::simulate(back));
  double z1 = kNaN, z2 = kNaN;
  const double f1 = mode_near(ex, 45.0, z1), f2 = mode_near(again, 45.0, z2);
  std::printf(
      "mode 45 Hz zeta 0.030 gain 0.15: found %.2f Hz zeta %.4f; written gain %.3f; the written scenario simulated: "
      "%.2f Hz zeta %.4f\n",
      f1, z1, back.resonance.modes[0].gain, f2, z2);
  EXPECT_NEAR(f1, 45.0, 2.0);
  EXPECT_NEAR(z1, 0.03, 0.009);
  EXPECT_NEAR(back.resonance.modes[0].gain, 0.15, 0.045);
  EXPECT_NEAR(f2, 45.0, 2.0);
  EXPECT_NEAR(z2, 0.03, 0.009);
}

}  // namespace
}  // namespace eical
