#pragma once
// The expanded uncertainty (GUM, k = 2) of every figure of an analysis: Monte Carlo
// propagation (GUM supplement 1) of the measurement's error field
// (uncertainty/error_field.hpp: integration noise and bias walk between the supports, the
// sensor model, the reference points) through the program's own evaluation.
//
// Each draw adds one realisation of the error to the measured path (decimated to about
// 1 kHz: the error is smooth and the figures do not need more) and evaluates the program
// again; the figure's spread over the draws is its standard uncertainty u. Figures that
// are not linear in the path (G = max − min, F, H, amplitudes, A, R) are biased by the
// noise: a draw adds noise to a path that already has it, so the draws' mean exceeds the
// measured value by about (√2 − 1) times the bias of the measured value against the truth
// (the bias of a max or an amplitude grows with σ). Hence
//   U = 2u + b/(√2 − 1),   b = |mean of the draws − value| less its Monte Carlo error,
// which is 2u for a linear figure and covers the bias of a range where noise dominates.
// The same draws are also added to the ideal path, the set-point, and evaluated: what the
// error alone makes of a figure. For a range, an amplitude or a spread the error of the
// figure is bounded by that (|f(t + e) − f(t)| ≤ f(e), a seminorm), whatever the machine:
// its 95 % bound |mean| + 2·sd is a floor under U — where the error is itself a shape (a
// scale mismatch drawing an ellipse) the plug-in alone would take it for the machine's.
#include "dsp/analysis/analyze_run.hpp"

namespace eical::dsp {

// Fills a.uncertainty_k2 (and its source and note) from the pipeline's configuration.
// Leaves it empty with a note when the measurement has no support schedule.
void estimate_uncertainty(const Run& run, const PipelineConfig& config, const AnalysisOptions& options, Analysis& a);

// U from the draws' mean offset and spread (see above); n draws.
double expanded_uncertainty(double mean_offset, double sd, int n);

}  // namespace eical::dsp
