#pragma once
// Unit conversions used across eical; names say the unit, these say the factor.
namespace eical::dsp::units {
inline constexpr double kPi = 3.14159265358979323846;
inline constexpr double kMmPerM = 1e3;
inline constexpr double kUmPerM = 1e6;
inline constexpr double kUmPerMm = 1e3;
inline constexpr double kMPerMm = 1e-3;
inline constexpr double kUgPerG = 1e6;
inline constexpr double kEarthRateRadps = 7.2921159e-5;  // sidereal rotation rate
inline constexpr double deg_to_rad(double deg) { return deg * kPi / 180.0; }
inline constexpr double mm_per_min_to_mps(double f) { return f / 60.0 / kMmPerM; }
}  // namespace eical::dsp::units
