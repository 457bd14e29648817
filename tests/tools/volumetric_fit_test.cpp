// eical volumetric --fit, round trip: a simulated machine with a known model (lead errors
// of x and y, a bow of x in y and of y in z, xy squareness) → ISO 230-2 runs of x and y →
// the fitted eical-volumetric/1 → its predictions at points no run stopped at, against the
// machine's truth, within the model's own uncertainty.
#include "drivers/run_io/run_writer.hpp"
#include "sim/simulate.hpp"
#include "tests/tools/cli_runner.hpp"
#include "tools/io/csv_table.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>

namespace {

namespace fs = std::filesystem;
using eical::tools::testing::run_cli;

constexpr double kScaleXPpm = 200.0, kScaleYPpm = -150.0, kBowXinYUm = 3.0, kBowYinZUm = 2.0, kSquarenessXyUrad = 60.0;
constexpr double kSpanMm = 25.0;  // the bows are zero at ±25 mm

eical::sim::Scenario machine(const std::string& axis, std::uint64_t seed) {
  auto sc = eical::sim::positioning_scenario({-20, -10, 0, 10, 20}, 3, 2000.0, seed);
  sc.meta.program.axis = axis;
  sc.meta.program.gcode.clear();
  sc.meta.id = "vol-" + axis;
  sc.machine.scale_ppm[0] = kScaleXPpm;
  sc.machine.scale_ppm[1] = kScaleYPpm;
  sc.machine.straightness[0] = {1, kBowXinYUm, {-kSpanMm, kSpanMm}};
  sc.machine.straightness[1] = {2, kBowYinZUm, {-kSpanMm, kSpanMm}};
  sc.machine.squareness_urad[0] = kSquarenessXyUrad;
  // The embedded calibrator's PSD strips at the origin: x and y fixes as the runs pass.
  eical::dsp::PsdSpec sx, sy;
  sx.measures = "x", sy.measures = "y";
  sc.meta.psd = {sx, sy};
  return sc;
}

// The machine's deviation at p (µm), as eical's simulator makes it (sim/machine: scale ×
// position, the bow b·(1 − u²) over the span, x −= ε·y for xy squareness).
Eigen::Vector3d truth_um(const Eigen::Vector3d& p) {
  auto bow = [](double b, double s) { return b * (1.0 - (s / kSpanMm) * (s / kSpanMm)); };
  return {kScaleXPpm * 1e-3 * p.x() - kSquarenessXyUrad * 1e-3 * p.y(),
          kScaleYPpm * 1e-3 * p.y() + bow(kBowXinYUm, p.x()), bow(kBowYinZUm, p.y())};
}

TEST(VolumetricFit, PredictsHeldOutPointsWithinItsUncertainty) {
  const fs::path dir = fs::temp_directory_path() / ("vol-fit-" + std::to_string(std::random_device{}()));
  fs::create_directories(dir);
  eical::drivers::write_run(eical::sim::simulate(machine("x", 11)), dir / "pos-x");
  eical::drivers::write_run(eical::sim::simulate(machine("y", 12)), dir / "pos-y");
  run_cli(
      {"volumetric", "--fit", (dir / "pos-x").string(), (dir / "pos-y").string(), "-o", (dir / "model.toml").string()});
  std::ifstream ms(dir / "model.toml");
  const std::string model{std::istreambuf_iterator<char>(ms), std::istreambuf_iterator<char>()};
  // Rotations and z are named as not observed, with the reason.
  EXPECT_NE(model.find("name = \"xrz\"\npositions_mm = [-20, 20]\nvalues = [0.0000, 0.0000]\nobserved = false\nnote = "
                       "\"not observable: a rotation"),
            std::string::npos)
      << model;
  EXPECT_NE(model.find("not measured: no positioning run moves z"), std::string::npos);

  // Held out: points between the targets and off the axes (the runs stood on x = 0 and y = 0).
  const std::vector<Eigen::Vector3d> held = {{-15, 5, 0}, {15, -15, 0},  {5, 15, 0},  {-5, -12, 0},
                                             {12, 8, 0},  {-18, -18, 0}, {18, 18, 0}, {0, 0, 0}};
  {
    std::ofstream p(dir / "p.csv");
    p << "x,y,z,xp,yp,zp\n";
    for (const auto& h : held) p << h.x() << "," << h.y() << "," << h.z() << ",0,0,0\n";
  }
  run_cli({"volumetric", "--model", (dir / "model.toml").string(), "--points", (dir / "p.csv").string(), "--out",
           (dir / "e.csv").string()});
  const eical::tools::CsvTable e(dir / "e.csv", {"ex_um", "ey_um", "ez_um", "Ux_um", "Uy_um", "Uz_um"}, {"status"});
  ASSERT_EQ(e.rows(), held.size());
  const std::size_t origin = held.size() - 1;
  const Eigen::Vector3d e0(e.number(origin, "ex_um"), e.number(origin, "ey_um"), e.number(origin, "ez_um"));
  const Eigen::Vector3d t0 = truth_um(Eigen::Vector3d::Zero());
  std::printf(
      "volumetric round trip (relative to the origin), um:\n   point              truth                 predicted      "
      "       U (k=2)\n");
  double worst_ratio = 0.0;
  for (std::size_t i = 0; i + 1 < held.size(); ++i) {
    const Eigen::Vector3d pred = Eigen::Vector3d(e.number(i, "ex_um"), e.number(i, "ey_um"), e.number(i, "ez_um")) - e0;
    const Eigen::Vector3d t = truth_um(held[i]) - t0;
    const Eigen::Vector3d u(e.number(i, "Ux_um"), e.number(i, "Uy_um"), e.number(i, "Uz_um"));
    std::printf("  (%5.1f,%5.1f)  %6.2f %6.2f %6.2f   %6.2f %6.2f %6.2f   %5.2f %5.2f %5.2f\n", held[i].x(),
                held[i].y(), t.x(), t.y(), t.z(), pred.x(), pred.y(), pred.z(), u.x(), u.y(), u.z());
    for (int c = 0; c < 3; ++c) {
      EXPECT_LE(std::abs(pred[c] - t[c]), u[c]) << "point " << i << " channel "
                                                << "xyz"[c];
      worst_ratio = std::max(worst_ratio, std::abs(pred[c] - t[c]) / u[c]);
    }
  }
  std::printf("  largest |predicted - truth| / U = %.2f\n", worst_ratio);
  if (!HasFailure()) fs::remove_all(dir);
}

}  // namespace
