#pragma once
// The "klipper-like" regime: a CoreXY printer's tool head under Klipper's resonance test,
// the real machine of issue 15 as eical's simulator makes it, with a known truth:
//  * the head's sensor only (the table triplex absent), a MEMS chip drawn per seed:
//    adxl345 at 3200, 1600, 800 or 400 Hz, lis2dw at 1600, 800 or 400 Hz, mpu6050 at 1000
//    or 400 Hz, each with its own corner (ODR/2 or 260 Hz: at or above Nyquist), noise
//    and resolution, and a bias of 1–5 mg per axis;
//  * Klipper's test on x or y from 5 to 133.33 Hz, the older executor or today's with the
//    slow sweep, from the first sample to the last (no standstill);
//  * two structural modes between drive and nozzle, 30–100 Hz, ζ 0.02–0.1 (log-uniform),
//    gain 0.1–0.8, within ±15° of the test axis in the XY plane (machine.resonance); in one
//    seed of three a close pair the data still resolve (apart by 1.5–2.5 times the sum of
//    their half-power half-widths ζ·f);
//  * the capture's clock (export): print-time offset 50–5000 s, jitter 2–10 % of a
//    sample, 0–4 lost batches of 8–32 samples.
// Hideable in it: machine.resonance (the modes) and sensor.misalignment (a wrong
// mounting: the head sensor truly mounted with a sign flip, a swap or a mirror).
#include "sim/regimes/capture_clock.hpp"
#include "sim/scenario.hpp"

#include <cstdint>
#include <string>
#include <vector>

namespace eical::sim {

inline constexpr const char* kKlipperLike = "klipper-like";

const std::vector<std::string>& klipper_like_effects();

// The regime's run for a seed with `effects` hidden (empty: the regime's baseline, no
// modes and the stated mounting). Throws InputError for an effect it cannot hide.
Scenario klipper_like_scenario(const std::vector<std::string>& effects, std::uint64_t seed);

// The capture clock of the seed's recording at fs_hz.
CaptureClock klipper_like_capture_clock(std::uint64_t seed, double fs_hz);

}  // namespace eical::sim
