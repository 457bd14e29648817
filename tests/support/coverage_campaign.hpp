#pragma once
// Is the uncertainty honest? A seeded campaign of simulated runs across test designs, each
// on a machine drawn within the data sheet's tolerances (the background of `eical simulate
// --background`: sensors, small machine errors, Earth rate, PSD strips), analysed like a
// real run; every figure is compared with the same evaluation of the simulator's true
// relative path. A figure is covered when |measured − true| ≤ U. Honest means the
// headline figures are covered in 90–99 % of the cases and U is not inflated: the median
// U is at most 2× the RMS error (for a Gaussian error U = 2σ gives 95 % and a ratio of 2).
// The table has each figure pooled over the designs and each headline figure per design
// (pooled, the designs with the largest errors set the RMS).
//
// Designs (kDesigns in the .cpp): the background circle (R 8–15 mm, PSD configuration B)
// and step; circles identified on site (R10–R50, both directions), with 4–16 strips
// (R25–R100, up to F10000) and beyond the instrument (R50–R150, two strips); ISO 230-2
// positioning over 30 mm and over 100–300 mm, with strips at mid travel or at both ends;
// a 40 × 30 mm rectangle — all on each seed's machine.
#include "dsp/analysis/figures.hpp"
#include "dsp/core/parallel_for.hpp"

#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace eical::coverage {

struct CampaignOptions {
  std::vector<std::uint64_t> seeds{1, 2, 3};
  std::vector<std::string> programs{"circle", "step", "positioning", "rectangle"};
  int draws = 100;
  dsp::ParallelFor parallel = dsp::sequential_for();  // the analyses' draws and smoother
  std::string write_runs;                             // a folder: every simulated run is written there (eical-run/1)
};

struct FigureCoverage {
  std::string key;
  std::size_t cases = 0, covered = 0;
  std::vector<double> u, abs_error;  // per case
  std::vector<double> u_over_bound;  // per case with a noise bound
  [[nodiscard]] double coverage() const {
    return cases ? static_cast<double>(covered) / static_cast<double>(cases) : 0.0;
  }
  [[nodiscard]] double median_u() const;
  [[nodiscard]] double rms_error() const;
};

struct CampaignResult {
  std::size_t runs = 0;
  std::vector<std::string> failures;  // runs that could not be analysed, why
  std::vector<std::string> misses;    // headline cases outside their U: run, figure, measured, true, U
  std::map<std::string, FigureCoverage> figures;
  // The headline figures per test design ("circle-strips circle.circular_deviation_G_um"):
  // pooled over designs, U/RMS compares the median U with an RMS that the designs with the
  // largest errors dominate; per design it says whether U is tight where the design puts it.
  std::map<std::string, FigureCoverage> headline_by_design;
  FigureCoverage headline;  // all headline figures pooled
  double seconds = 0.0;
};

// The headline figures of each program (the ones the campaign must cover).
const std::vector<std::string>& headline_keys();

CampaignResult run_campaign(const CampaignOptions& options);

// The coverage table as bench_uncertainty prints it.
std::string coverage_table(const CampaignResult& result);

}  // namespace eical::coverage
