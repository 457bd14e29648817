#pragma once
// What the user signs against: tolerances per figure and the report's header, from a
// tolerance file (eical-tolerances/1, strict TOML):
//
//   format = "eical-tolerances/1"
//   [header]                    # all optional: printed in the report's header
//   machine = "DMU 50"          # overrides run.toml's [machine] name
//   serial = "12345"
//   operator = "A. Tester"
//   [circle]                    # ISO 230-4
//   G_um = 15.0                 # circular deviation
//   F_um = 10.0                 # radial deviation: |F max| and |F min|
//   [positioning]               # ISO 230-2, bidirectional
//   A_um = 12.0
//   B_um = 4.0
//   R_um = 6.0
//   E_um = 8.0
//   M_um = 6.0
//
// The decision follows ISO 14253-1 with the expanded uncertainty U (k = 2): "pass" when
// the figure plus U is within the tolerance, "fail" when the figure minus U is beyond
// it, "undecided" between (the measurement cannot tell).
#include "dsp/analysis/analyze_run.hpp"

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace eical::tools::report {

struct Tolerances {
  std::string machine, serial, operator_name;
  std::optional<double> G_um, F_um;                    // ISO 230-4
  std::optional<double> A_um, B_um, R_um, E_um, M_um;  // ISO 230-2
};

// Throws InputError naming the file, line and key.
Tolerances read_tolerances(const std::filesystem::path& file);

struct ToleranceDecision {
  std::string figure;       // "Circular deviation G"
  double value = 0.0;       // the magnitude compared
  std::optional<double> u;  // its U (k = 2)
  double tolerance = 0.0;
  std::string decision;  // pass | fail | undecided
};

// Every toleranced figure the analysis has.
std::vector<ToleranceDecision> decide(const dsp::Analysis& a, const Tolerances& t);

// ISO 14253-1: pass when value + U <= tolerance, fail when value − U > tolerance.
std::string decision(double value, std::optional<double> u, double tolerance);

}  // namespace eical::tools::report
