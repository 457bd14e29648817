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
// The decision follows ISO 14253-1 with the expanded uncertainty U (k = 2)
// (dsp/analysis/conformance.hpp): conformance proven when the figure plus U is within the
// tolerance, non-conformance proven when the figure minus U is beyond it, undecided between
// (the measurement cannot tell). `eical analyze --tolerances` and `eical report
// --tolerances` read the same file and decide the same way.
#include "dsp/analysis/conformance.hpp"

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

// The tolerances on result keys, in the order a report lists them.
std::vector<dsp::FigureTolerance> figure_tolerances(const Tolerances& t);

}  // namespace eical::tools::report
