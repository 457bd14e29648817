// The regime keys of scenario files (config/scenarios/README.md): the examples load into
// what they say, and bad values are named with the file, line and key.
#include "drivers/config/scenario_file.hpp"
#include "drivers/run_io/run_writer.hpp"
#include "dsp/core/error.hpp"
#include "sim/effects.hpp"
#include "sim/simulate.hpp"

#include <gtest/gtest.h>

#include <filesystem>

namespace eical {
namespace {

TEST(RegimeScenarios, KlipperLikeExampleIsWhatItSays) {
  sim::Scenario sc = drivers::read_scenario_file(EICAL_SOURCE_DIR "/config/scenarios/klipper-like.toml");
  EXPECT_FALSE(sc.meta.sensor_present[0]);
  EXPECT_TRUE(sc.meta.sensor_present[1]);
  EXPECT_EQ(sc.meta.sensors[1].model, "adxl345");
  EXPECT_EQ(sc.meta.acquisition.adc_bits, 13);
  EXPECT_DOUBLE_EQ(sc.meta.acquisition.adc_lsb_volt, 32.0 / 8192.0);
  EXPECT_DOUBLE_EQ(sc.meta.sensors[1].f0_hz, 1600.0);
  EXPECT_FALSE(sc.daq.anti_alias_filter);
  EXPECT_NEAR(sc.truth[1].spec.bias_g.y(), -3.4e-3, 1e-12);
  EXPECT_TRUE(sc.sweep.on);
  EXPECT_TRUE(sc.sweep.test.legacy_moves);
  EXPECT_EQ(sc.meta.program.kind, eical::dsp::ProgramKind::freeform);
  ASSERT_EQ(sc.resonance.modes.size(), 2u);
  EXPECT_DOUBLE_EQ(sc.resonance.modes[1].frequency_hz, 67.0);
  EXPECT_EQ(sim::effect_lists(sc).present, std::vector<std::string>{"machine.resonance"});
  sc.sweep.test.freq_end_hz = 8.0;  // a short piece of it
  const dsp::Run run = sim::simulate(sc);
  EXPECT_EQ(run.frames.front().trigger, 101);
  EXPECT_NE(run.truth_toml->find("[nc.sweep]"), std::string::npos);
  EXPECT_NE(run.truth_toml->find("frequency_hz = 41.0"), std::string::npos);
}

TEST(RegimeScenarios, MirroredSweepExampleIsWhatItSays) {
  const sim::Scenario sc = drivers::read_scenario_file(EICAL_SOURCE_DIR "/config/scenarios/mirrored-sweep.toml");
  EXPECT_EQ(sc.truth[1].axes_map, "-x,y,z");
  EXPECT_DOUBLE_EQ(sc.truth[1].spec.to_machine(0, 0), -1.0);
  EXPECT_DOUBLE_EQ(sc.truth[0].spec.to_machine(0, 0), 1.0);
  EXPECT_TRUE(sc.daq.anti_alias_filter);
  EXPECT_DOUBLE_EQ(sc.sweep.direction.y(), 1.0);
  EXPECT_DOUBLE_EQ(sc.sweep.lead_in_s, 0.5);
  EXPECT_EQ(sim::effect_lists(sc).present, (std::vector<std::string>{"sensor.misalignment", "machine.resonance"}));
}

TEST(RegimeScenarios, BadRegimeKeysAreNamedWithTheLine) {
  const auto file = std::filesystem::temp_directory_path() / "eical-regime-scenario.toml";
  auto error_of = [&](const std::string& body) {
    drivers::write_text_atomic(file, "format = \"eical-scenario/1\"\n" + body);
    try {
      drivers::read_scenario_file(file.string());
    } catch (const dsp::InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(error_of("[mems]\nchip = \"adxl999\"\n[sweep]\n").find("chip"), std::string::npos);
  EXPECT_NE(error_of("[mems]\nbits = 40\n[sweep]\n").find(":3:"), std::string::npos);
  EXPECT_NE(error_of("[sweep]\nhz_per_sec = 5.0\n").find("hz_per_sec must be in (0, 2]"), std::string::npos);
  EXPECT_NE(error_of("[sweep]\naxis = \"w\"\n").find("axis"), std::string::npos);
  EXPECT_NE(error_of("sensors_present = \"none\"\n[sweep]\n").find("sensors_present"), std::string::npos);
  EXPECT_NE(error_of("[sweep]\n[effects.\"machine.resonance\"]\npart = \"head\"\n").find("modes"), std::string::npos);
  const std::string zeta = error_of(
      "[sweep]\n[effects.\"machine.resonance\"]\n[[effects.\"machine.resonance\".modes]]\nfrequency_hz = "
      "40.0\ndamping_ratio = 1.5\ngain = 0.1\n");
  EXPECT_NE(zeta.find(":6:"), std::string::npos) << zeta;
  EXPECT_NE(zeta.find("damping_ratio"), std::string::npos) << zeta;
  EXPECT_NE(error_of("[sweep]\n[effects.\"sensor.misalignment\"]\naxes_map = \"x,x,z\"\n").find("x appears twice"),
            std::string::npos);
  EXPECT_NE(error_of("[sweep]\n[program]\nkind = \"freeform\"\ngcode_file = \"a.ngc\"\n").find("runs Klipper's test"),
            std::string::npos);
  EXPECT_NE(error_of("[mems]\nchip = \"lis2dw\"\nfrequency = 3\n[sweep]\n").find("frequency"), std::string::npos);
  std::filesystem::remove(file);
}

}  // namespace
}  // namespace eical
