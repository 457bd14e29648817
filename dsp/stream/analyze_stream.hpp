#pragma once
// analyze_run() for a run of any length in bounded memory. The frames are read twice,
// never held: the first pass runs the pipeline keeping only what the offline smoother
// reads (TraceKeeping::track, a few bytes per sample) and decides from the set-point
// alone what needs no measurement (the circle's stretches, the repeats' groups); the
// smoother then runs checkpointed; the second pass replays the frames for the integrated
// trace, applies the smoothed corrections segment by segment and the DAQ delay, and hands
// each corrected sample to the evaluation as it goes by. A circle is evaluated as it
// streams (one revolution in memory, the diagnostics' and the repeats' samples in spills
// read back from disk); other programs keep their whole trace and are evaluated by
// evaluate_measurement(), as analyze_run() does. Analysis::measurement keeps about
// StreamOptions::measurement_points samples of a longer trace (every n-th, for plots);
// the uncertainty's Monte Carlo reads every sample it needs as it goes by (UncertaintyTrace).
//
// The figures and their uncertainty equal analyze_run()'s: the same stages in the same
// order on the same numbers (tests/e2e/analyze_stream_test.cpp compares every number of
// the result).
#include "dsp/analysis/analyze_run.hpp"
#include "dsp/core/spill.hpp"
#include "dsp/stream/frame_replay.hpp"

#include <cstddef>

namespace eical::dsp {

struct StreamOptions {
  SpillFactory spills = memory_spills();   // where evaluations keep samples they read again
  std::size_t measurement_points = 50000;  // Analysis::measurement of a longer circle run: every n-th sample
  // Up to this many trace samples (a minute at 10 kHz, about 100 MB) the trace is kept
  // whole and evaluated as analyze_run() does; a longer circle is evaluated as it streams,
  // its uncertainty from what UncertaintyTrace collects on the way (the same draws).
  std::size_t materialize_samples = 600000;
  // The second pass reads the first pass's integrated trace from a spill (112 B a sample
  // on disk) instead of running the frames through the pipeline again: for frames that
  // are slow to read (a CSV file); frames in memory replay faster than a spill reads.
  bool spill_trace = false;
  // The smoother's corrections kept in a spill as it makes them (72 B a sample) instead of
  // recomputed segment by segment in the second pass (two of the smoother's five passes).
  bool spill_corrections = false;
};

// header: the run's metadata and channels (its frames are not read; `frames` is).
// Throws InputError as analyze_run() does, and on bad input met while reading.
Analysis analyze_stream(const Run& header, FrameReplay& frames, const AnalysisOptions& options,
                        const StreamOptions& stream = {});

}  // namespace eical::dsp
