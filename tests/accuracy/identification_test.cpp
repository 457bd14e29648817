// On-site identification against the simulator's truth: a table sensor rotated, scaled
// and cross-coupled, with its own f0 and ζ, and a head sensor scaled on z, identified from
// the identification program's PSD readings and set-point alone; every fitted term must
// land within its stated uncertainty (4 σ, at least 30 ppm) of the truth.
#include "dsp/core/error.hpp"
#include "dsp/identify/sensor_identification.hpp"
#include "sim/simulate.hpp"
#include "tools/demo/demo_stages.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <cmath>
#include <cstdio>
#include <numbers>

namespace eical {
namespace {

// measured = (I + E) · true in machine axes, for a sensor whose linear model is
// u = k1_true (I + kx) T_true⁻¹ a, compensated with the data sheet (k1, T).
Eigen::Matrix3d true_error(const sim::SensorTruth& t, const dsp::SensorSpec& sheet) {
  const Eigen::Vector3d ratio = t.spec.k1_v_per_g.cwiseQuotient(sheet.k1_v_per_g);
  return sheet.to_machine * ratio.asDiagonal() * (Eigen::Matrix3d::Identity() + t.k_cross_g_per_g) *
             t.spec.to_machine.inverse() -
         Eigen::Matrix3d::Identity();
}

double damping_s(const dsp::SensorSpec& s) { return 2.0 * s.zeta / (2.0 * std::numbers::pi * s.f0_hz); }

TEST(Identification, RecoversScaleMountingCrossTermsAndDampingWithinTheirUncertainty) {
  sim::Scenario sc = sim::identify_scenario(sim::psd_config_b(10.0), {"z"}, 4);
  auto& t = sc.truth[0];
  t.spec.k1_v_per_g[0] *= 1.004, t.spec.k1_v_per_g[1] *= 0.997;
  t.spec.to_machine =
      (Eigen::AngleAxisd(0.004, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(0.002, Eigen::Vector3d::UnitX()))
          .toRotationMatrix();
  t.k_cross_g_per_g(0, 1) = 1e-3;
  t.spec.f0_hz = 920.0, t.spec.zeta = 0.6;
  sc.truth[1].spec.k1_v_per_g[2] *= 1.003;
  const dsp::Run run = sim::simulate(sc);
  const dsp::identify::Identification id = dsp::identify::identify_sensors(run);

  for (int s = 0; s < 2; ++s) {
    const Eigen::Matrix3d e = true_error(sc.truth[s], sc.meta.sensors[s]);
    const auto& se = id.sensor[s];
    ASSERT_TRUE(se.moved);
    int fitted = 0;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        const auto& est = se.error[i][j];
        if (!est.fitted) continue;
        ++fitted;
        EXPECT_NEAR(est.value, e(i, j), std::max(4.0 * est.sigma, 30e-6))
            << "sensor " << s << " E(" << i << "," << j << ")";
        EXPECT_LT(est.sigma, 1e-4);
      }
    EXPECT_EQ(fitted, s == 0 ? 6 : 3);  // the table carries x and y, the head z
  }
  const double dc = damping_s(sc.meta.sensors[0]) - damping_s(sc.truth[0].spec);
  ASSERT_TRUE(id.sensor[0].damping_s.fitted);
  EXPECT_NEAR(id.sensor[0].damping_s.value, dc, std::max(4.0 * id.sensor[0].damping_s.sigma, 1e-6));
  EXPECT_FALSE(id.sensor[1].damping_s.fitted);  // z has no strip: data sheet kept, and said
  // The simulated runs carry an ideal reference: the delay against it is the DAQ's own.
  ASSERT_TRUE(id.delay_reference.valid);
  EXPECT_NEAR(id.delay_reference.samples, 38.8, std::max(4.0 * id.delay_reference.sigma, 0.05));
  // The identified model explains the PSD readings better than the data sheet.
  EXPECT_LT(id.psd_rms_after_um, 0.5 * id.psd_rms_before_um);
  // Applied, the sensors are the truth again: scale within 40 ppm.
  dsp::RunMeta meta = run.meta;
  dsp::identify::apply_identification(id, meta);
  const Eigen::Matrix3d residual = true_error(sc.truth[0], meta.sensors[0]);
  EXPECT_LT((residual.topLeftCorner(2, 2).cwiseAbs().maxCoeff()), 40e-6);
}

// A strip reads u (1 + nl (2u/L)²): across its length that is a slope of 0.6·nl, a scale
// error of the axis it measures (60 ppm at the data sheet's bound). Taken for the truth it
// moved the identified scale by that much; fitted beside the scale, it does not.
TEST(Identification, AStripsNonlinearityIsNotTakenForTheSensorsScale) {
  double scale_at[2][2] = {};  // [nl + or −][axis]
  for (int sign = 0; sign < 2; ++sign) {
    const double nl = sign == 0 ? 1e-4 : -1e-4;
    sim::Scenario sc = sim::identify_scenario(sim::psd_config_b(10.0), {"z"}, 5);  // the same noise twice
    sc.psd.assign(sc.meta.psd.size(), sim::PsdTruth{});
    for (auto& strip : sc.psd) strip.nonlinearity = nl;
    const dsp::identify::Identification id = dsp::identify::identify_sensors(sim::simulate(sc));
    const Eigen::Matrix3d e = true_error(sc.truth[0], sc.meta.sensors[0]);
    for (int i = 0; i < 2; ++i) {
      const auto& est = id.sensor[0].error[i][i];
      ASSERT_TRUE(est.fitted);
      std::printf("nl %+.0e: E(%d,%d) %+.1f ppm, true %+.1f ppm, sigma %.1f ppm\n", nl, i, i, est.value * 1e6,
                  e(i, i) * 1e6, est.sigma * 1e6);
      EXPECT_NEAR(est.value, e(i, i), 3.0 * est.sigma) << "nl " << nl << ", E(" << i << "," << i << ")";
      scale_at[sign][i] = est.value;
    }
    for (const auto& strip_nl : id.psd_nonlinearity) {  // and the strips' own, from their shape
      ASSERT_TRUE(strip_nl.fitted);
      EXPECT_NEAR(strip_nl.value, nl, 3.0 * strip_nl.sigma);
      EXPECT_LT(strip_nl.sigma, 0.5e-4);
    }
  }
  // Taken for the truth, ±1e-4 moved the scale by ±60 ppm: 120 ppm apart.
  for (int i = 0; i < 2; ++i) EXPECT_LT(std::abs(scale_at[0][i] - scale_at[1][i]), 30e-6) << "axis " << i;
}

// The demo's identification (R10, strips in configuration B, drawn sensors): its strips are
// crossed at most at 6.5 m/min, where 2ζ/ω0·v is a fraction of a µm, and its damping term
// alone came out ± 3.0 µs against the data sheet's ± 2.25: `eical identify` refused the
// calibration the demo had just used. Weighed with the data sheet it is never less certain.
TEST(Identification, ADampingTermLessCertainThanTheDataSheetIsWeighedWithIt) {
  const tools::demo::DemoMachine m = tools::demo::demo_machine(1, {});
  const dsp::Run run = sim::simulate(m.identification);
  const dsp::identify::Identification id = dsp::identify::identify_sensors(run);
  const auto ds = dsp::datasheet_covariance(run.meta.sensors, run.meta.acquisition.fs_hz);
  EXPECT_TRUE(dsp::identify::less_certain_than_datasheet(id, ds).empty());
  int weighed = 0;
  for (int s = 0; s < 2; ++s) {
    const auto& d = id.sensor[s].damping_s;
    if (!d.fitted) continue;
    const int p = dsp::damping_index(s);
    const double run_only = 1.5 * d.sigma;  // what the calibration carried alone (its margin)
    const double w0 = 2.0 * std::numbers::pi * run.meta.sensors[s].f0_hz;
    const double applied = 2.0 * run.meta.sensors[s].zeta / w0 - 2.0 * id.sensors[s].zeta / w0;
    std::printf(
        "sensor %d: 2zeta/omega0 from the data sheet's %+.2f +- %.2f us alone, data sheet +- %.2f, applied %+.2f +- "
        "%.2f us, true %+.2f us\n",
        s, d.value * 1e6, run_only * 1e6, ds.sigma(p) * 1e6, applied * 1e6, id.covariance.sigma(p) * 1e6,
        (damping_s(run.meta.sensors[s]) - damping_s(m.identification.truth[s].spec)) * 1e6);
    EXPECT_LE(id.covariance.sigma(p), ds.sigma(p));
    if (run_only <= ds.sigma(p)) continue;
    ++weighed;
    // The applied ζ lies between the data sheet's and the run's alone.
    EXPECT_LT(std::abs(applied), std::abs(d.value) + 1e-12);
    EXPECT_GE(applied * d.value, 0.0);
  }
  EXPECT_GE(weighed, 1) << "the case this test is about did not occur";
}

TEST(Identification, ARunWithoutMotionOrStandstillIsAClearError) {
  dsp::Run run = sim::simulate(sim::identify_scenario(sim::psd_config_b(10.0), {}, 1));
  run.frames.resize(3000);  // the rest before the first move only
  try {
    (void)dsp::identify::identify_sensors(run);
    FAIL() << "identified from a run without motion";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("identify"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace eical

namespace eical {
namespace {

// A run that cannot identify the sensors is refused with the reason: a circle crosses its
// strips at one speed and rests once; the identification program passes and carries a
// covariance no worse than the data sheet's.
TEST(Identification, ACircleRunIsRefusedWithTheReason) {
  sim::Scenario sc = sim::circle_scenario(10.0, 2500.0, 5, "ccw", 1);
  sc.meta.psd = sim::psd_config_b(10.0);
  try {
    (void)dsp::identify::identify_sensors(sim::simulate(sc));
    FAIL() << "identified from a circle";
  } catch (const dsp::InputError& e) {
    const std::string w = e.what();
    EXPECT_TRUE(w.find("rests only once") != std::string::npos || w.find("one speed") != std::string::npos) << w;
    EXPECT_NE(w.find("eical gen-nc identify"), std::string::npos) << w;
  }
}

TEST(Identification, ARunWithoutStripsIsRefused) {
  try {
    (void)dsp::identify::identify_sensors(sim::simulate(sim::step_scenario(0.0, 50.0, 3250.0, 2, 1)));
    FAIL() << "identified from a step without PSD strips";
  } catch (const dsp::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("has no PSD strips"), std::string::npos) << e.what();
  }
}

TEST(Identification, TheCalibrationCarriesACovarianceWithinTheDataSheetsTolerance) {
  const dsp::Run run = sim::simulate(sim::identify_scenario(sim::psd_config_b(10.0), {"z"}, 2));
  const dsp::identify::Identification id = dsp::identify::identify_sensors(run);
  const auto ds = dsp::datasheet_covariance(run.meta.sensors, run.meta.acquisition.fs_hz);
  EXPECT_TRUE(dsp::identify::less_certain_than_datasheet(id, ds).empty());
  EXPECT_GE(id.crossing_speeds_mm_s.size(), 3u);  // 2, 4 and 6.5 m/min
  // The fitted terms: the identification's own σ with its margin (a strip's nonlinearity is
  // fitted beside the scale it measures: in that σ), well below the data sheet's.
  const int xx = dsp::error_index(0, 0, 0), xy = dsp::error_index(0, 0, 1);
  EXPECT_NEAR(id.covariance.sigma(xy), 1.5 * id.sensor[0].error[0][1].sigma, 1e-12);
  EXPECT_NEAR(id.covariance.sigma(xx), 1.5 * id.sensor[0].error[0][0].sigma, 1e-12);
  EXPECT_LT(id.covariance.sigma(xx), 0.2 * ds.sigma(xx));
  // Terms it did not fit keep the data sheet's.
  EXPECT_DOUBLE_EQ(id.covariance.sigma(dsp::error_index(1, 0, 0)), ds.sigma(dsp::error_index(1, 0, 0)));
  // A fitted term as uncertain as the circle's E_zx is reported as worse than the data sheet.
  dsp::identify::Identification bad = id;
  bad.sensor[0].error[2][0] = {-3778e-6, 14106e-6, true};
  const int zx = dsp::error_index(0, 2, 0);
  bad.covariance.covariance(zx, zx) = 14106e-6 * 14106e-6;
  const auto worse = dsp::identify::less_certain_than_datasheet(bad, ds);
  ASSERT_EQ(worse.size(), 1u);
  EXPECT_NE(worse[0].find("table.E_zx"), std::string::npos) << worse[0];
}

}  // namespace
}  // namespace eical
