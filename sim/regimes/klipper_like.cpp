#include "sim/regimes/klipper_like.hpp"

#include "dsp/core/error.hpp"
#include "sim/regimes/regimes.hpp"
#include "sim/simulate.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

namespace eical::sim {
namespace {

struct Draw {
  std::mt19937_64 rng;
  explicit Draw(std::uint64_t seed) : rng(seed) {}
  double u(double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(rng); }
  double mag(double lo, double hi) { return (u(0, 1) < 0.5 ? -1.0 : 1.0) * u(lo, hi); }
  int pick(int n) { return std::uniform_int_distribution<int>(0, n - 1)(rng); }
};

struct ChipRate {
  const char* chip;
  double fs_hz;
};
constexpr ChipRate kChipRates[] = {{"adxl345", 3200.0}, {"adxl345", 1600.0}, {"adxl345", 800.0},
                                   {"adxl345", 400.0},  {"lis2dw", 1600.0},  {"lis2dw", 800.0},
                                   {"lis2dw", 400.0},   {"mpu6050", 1000.0}, {"mpu6050", 400.0}};

// Mountings a user can state wrongly: a 180° turn about z, a swap (mirror), one axis
// negated (mirror), a 90° turn about z, the board upside down (180° about x).
constexpr const char* kWrongMountings[] = {"-x,-y,z", "y,x,z", "-x,y,z", "y,-x,z", "x,-y,-z"};

}  // namespace

const std::vector<std::string>& klipper_like_effects() {
  static const std::vector<std::string> e = {"machine.resonance", "sensor.misalignment"};
  return e;
}

Scenario klipper_like_scenario(const std::vector<std::string>& effects, std::uint64_t seed) {
  for (const auto& e : effects)
    if (std::find(klipper_like_effects().begin(), klipper_like_effects().end(), e) == klipper_like_effects().end())
      throw dsp::InputError(std::string("regime ") + kKlipperLike + ": cannot hide '" + e +
                            "' (it hides machine.resonance and sensor.misalignment)");
  Draw d(stream_seed(seed, 8001));
  const bool legacy = d.pick(2) == 0;
  nc::KlipperTest test = legacy ? nc::KlipperTest::legacy() : nc::KlipperTest::current();
  test.freq_end_hz = 10000.0 / 75.0;
  const int axis = d.pick(2);  // x or y
  Scenario sc = sweep_scenario(test, axis == 0 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY(), seed);
  sc.meta.reference.reset();  // a printer has no cross-grid encoder
  sc.meta.machine.name = "sim-corexy";
  sc.meta.machine.head_axes = {"x", "y"};
  sc.meta.machine.table_axes = {"z"};
  sc.meta.site.latitude_deg = d.u(35.0, 60.0), sc.meta.site.heading_deg = d.u(0.0, 360.0);
  sc.coriolis = true;
  const ChipRate cr = kChipRates[d.pick(static_cast<int>(std::size(kChipRates)))];
  apply_mems(sc, mems_chip(cr.chip), cr.fs_hz,
             Eigen::Vector3d(d.mag(1e-3, 5e-3), d.mag(1e-3, 5e-3), d.mag(1e-3, 5e-3)));
  set_sensors_present(sc, "head");
  // Each hideable effect from its own stream: its draw does not depend on the other.
  auto has = [&](const char* e) { return std::find(effects.begin(), effects.end(), e) != effects.end(); };
  Draw dm(stream_seed(seed, 8002));
  // Printers' modes: ζ 0.02–0.1 (log-uniform), peaks of ×1.5–40 (gain/2ζ). One seed in
  // three holds a close pair, apart by 1.5–2.5 times the sum of their half-power
  // half-widths: two modes the data resolve.
  const double z1 = 0.02 * std::pow(5.0, dm.u(0.0, 1.0)), z2 = 0.02 * std::pow(5.0, dm.u(0.0, 1.0));
  const double f1 = dm.u(30.0, 65.0);
  const bool close = dm.u(0.0, 1.0) < 1.0 / 3.0;
  const double f2 = close ? f1 + std::max(3.0, dm.u(1.5, 2.5) * (z1 + z2) * f1) : dm.u(f1 + 8.0, 80.0);
  for (const auto& [f, z] : {std::pair{f1, z1}, std::pair{f2, z2}}) {
    const double tilt = dm.u(-15.0, 15.0) * std::numbers::pi / 180.0, base = axis == 0 ? 0.0 : std::numbers::pi / 2.0;
    StructuralMode m;
    m.frequency_hz = f, m.damping_ratio = z, m.gain = dm.u(0.1, 0.8);
    m.direction = Eigen::Vector3d(std::cos(base + tilt), std::sin(base + tilt), 0.0);
    if (has("machine.resonance")) sc.resonance.modes.push_back(m);
  }
  sc.resonance.part = 1;
  Draw dw(stream_seed(seed, 8003));
  const char* mounting = kWrongMountings[dw.pick(static_cast<int>(std::size(kWrongMountings)))];
  if (has("sensor.misalignment")) apply_wrong_mounting(sc, 1, mounting);
  sc.effects_present = effects;
  sc.effects_background = {"site.coriolis"};
  std::string name = effects.empty() ? "baseline" : effects.front();
  for (std::size_t i = 1; i < effects.size(); ++i) name.append("+").append(effects[i]);
  // Appended piecewise: GCC 12 at -O2 warns falsely (-Warray-bounds) on chained operator+.
  sc.name = std::string(kKlipperLike).append(":").append(name);
  sc.meta.id = std::string(kKlipperLike).append("-").append(name).append("-s").append(std::to_string(seed));
  sc.description = std::string(kKlipperLike)
                       .append(" regime: ")
                       .append(cr.chip)
                       .append(" at ")
                       .append(std::to_string(static_cast<int>(cr.fs_hz)));
  sc.description.append(" Hz on the head, ")
      .append(legacy ? "older" : "current")
      .append(" Klipper test on ")
      .append(axis == 0 ? "x, " : "y, ")
      .append(name);
  return sc;
}

CaptureClock klipper_like_capture_clock(std::uint64_t seed, double fs_hz) {
  Draw d(stream_seed(seed, 8004));
  CaptureClock c;
  c.offset_s = d.u(50.0, 5000.0);
  c.jitter_rms_s = d.u(0.02, 0.10) / fs_hz;
  c.batch = 8 + d.pick(25);
  c.lost_batches = d.pick(5);
  c.seed = stream_seed(seed, 8005);
  return c;
}

}  // namespace eical::sim
