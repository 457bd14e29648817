// The streamed analysis (dsp/stream) against analyze_run() on the same short runs: every
// number, string and flag of the eical-result/1 document equal (U and the verdict too) —
// circles in both directions (revolutions, H, repeats, diagnostics, the reference channel), partial arcs,
// PSD strips, lost and bad frames, the other programs; from memory and read from disk as
// eical analyze reads a run (samples.csv and .gz, a sensor absent, spills in files), and
// with the per-sample arrays thinned as for a long run.
#include "dsp/stream/analyze_stream.hpp"
#include "drivers/results/result_json.hpp"
#include "drivers/run_io/file_spill.hpp"
#include "drivers/run_io/run_reader.hpp"
#include "drivers/run_io/run_stream.hpp"
#include "drivers/run_io/run_writer.hpp"
#include "dsp/analysis/analyze_run.hpp"
#include "dsp/core/error.hpp"
#include "dsp/core/float_limits.hpp"
#include "sim/simulate.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

namespace eical {
namespace {

namespace fs = std::filesystem;

// Walks two result documents; numbers must agree to 1e-12 (relative), all else exactly.
void expect_same(const nlohmann::json& a, const nlohmann::json& b, const std::string& path, int& differences) {
  if (differences > 20) return;
  if (a.is_number() && b.is_number()) {
    const double x = a.get<double>(), y = b.get<double>();
    if (x == y || std::abs(x - y) <= 1e-12 * std::max(std::abs(x), std::abs(y))) return;
    ADD_FAILURE() << path << ": " << x << " vs " << y;
    ++differences;
    return;
  }
  if (a.type() != b.type()) {
    ADD_FAILURE() << path << ": " << a.dump() << " vs " << b.dump();
    ++differences;
    return;
  }
  if (a.is_object()) {
    for (const auto& [k, v] : a.items()) {
      if (!b.contains(k)) {
        ADD_FAILURE() << path << "." << k << " missing in the streamed result";
        ++differences;
        continue;
      }
      expect_same(v, b[k], path + "." + k, differences);
    }
    for (const auto& [k, v] : b.items())
      if (!a.contains(k)) ADD_FAILURE() << path << "." << k << " only in the streamed result", ++differences;
    return;
  }
  if (a.is_array()) {
    if (a.size() != b.size()) {
      ADD_FAILURE() << path << ": " << a.size() << " vs " << b.size() << " elements";
      ++differences;
      return;
    }
    for (std::size_t i = 0; i < a.size(); ++i)
      expect_same(a[i], b[i], path + "[" + std::to_string(i) + "]", differences);
    return;
  }
  if (a != b) ADD_FAILURE() << path << ": " << a.dump() << " vs " << b.dump(), ++differences;
}

void expect_same_result(const dsp::Run& run, const dsp::Analysis& whole, const dsp::Analysis& streamed) {
  int differences = 0;
  expect_same(drivers::result_json(run, whole), drivers::result_json(run, streamed), "", differences);
  EXPECT_EQ(whole.flags, streamed.flags);
  EXPECT_EQ(whole.degraded, streamed.degraded);
}

// The figures and their uncertainty (fewer draws than eical analyze's 100, the same
// draws both ways: the result documents compare U and the verdict too).
dsp::AnalysisOptions with_uncertainty() {
  dsp::AnalysisOptions o;
  o.uncertainty.draws = 12;
  return o;
}

dsp::Analysis whole_trace(const dsp::Run& run) { return dsp::analyze_run(run, with_uncertainty()); }

// Streamed however short the run (materialize_samples 0).
dsp::Analysis streamed(const dsp::Run& run, std::size_t measurement_points = 50000) {
  dsp::StoredFrames frames(run.frames);
  dsp::StreamOptions so;
  so.measurement_points = measurement_points;
  so.materialize_samples = 0;
  return dsp::analyze_stream(run, frames, with_uncertainty(), so);
}

sim::Scenario circle(double radius, double feed, int repeats, const std::string& direction) {
  sim::Scenario sc = sim::circle_scenario(radius, feed, repeats, direction);
  return sc;
}

TEST(AnalyzeStream, CircleBothDirectionsEqualsTheWholeTraceAnalysis) {
  const dsp::Run run = sim::simulate(circle(10.0, 2500.0, 3, "both"));
  const dsp::Analysis whole = whole_trace(run);
  ASSERT_TRUE(whole.circle && whole.diagnostics && whole.circle_accuracy_rms_um)
      << (whole.flags.empty() ? "" : flag_text(whole.flags.front()));
  ASSERT_EQ(whole.repeats.size(), 2u);  // three revolutions each way
  const dsp::Analysis s = streamed(run);
  expect_same_result(run, whole, s);
  // The figures are the same numbers, not merely close ones.
  EXPECT_EQ(s.circle->circular_deviation_G_um, whole.circle->circular_deviation_G_um);
  EXPECT_EQ(*s.circle->circular_hysteresis_H_um, *whole.circle->circular_hysteresis_H_um);
  EXPECT_EQ(s.repeats[0].scatter_rms_um, whole.repeats[0].scatter_rms_um);
  EXPECT_EQ(s.diagnostics->backlash_x_um, whole.diagnostics->backlash_x_um);
}

TEST(AnalyzeStream, ThinnedArraysOfALongRunKeepEveryFigure) {
  const dsp::Run run = sim::simulate(circle(10.0, 2500.0, 2, "both"));
  const dsp::Analysis whole = whole_trace(run);
  const dsp::Analysis s = streamed(run, 500);  // as if the run were a hundred times longer
  EXPECT_GT(s.measurement.decimation, 1u);
  EXPECT_LE(s.measurement.sample_index.size(), 502u);
  EXPECT_EQ(s.measurement.trace_samples, whole.measurement.sample_index.size());
  EXPECT_EQ(s.measurement.sample_index.back(), whole.measurement.sample_index.back());
  EXPECT_GT(s.circle->trace.stride, 1u);
  expect_same_result(run, whole, s);
}

TEST(AnalyzeStream, PartialArcsPsdStripsAndOneDirection) {
  sim::Scenario arc = circle(10.0, 2000.0, 1, "both");
  arc.meta.program.plane = "yz";
  arc.meta.program.arc_deg = 220.0;
  sim::Scenario psd = circle(10.0, 2500.0, 2, "ccw");
  psd.meta.psd = sim::psd_config_b(10.0);
  for (const auto& sc : {arc, psd}) {
    const dsp::Run run = sim::simulate(sc);
    const dsp::Analysis whole = whole_trace(run);
    ASSERT_TRUE(whole.circle) << (whole.flags.empty() ? "" : flag_text(whole.flags.front()));
    expect_same_result(run, whole, streamed(run));
  }
}

TEST(AnalyzeStream, LostAndBadFramesAndRunsWithoutTriggers) {
  dsp::Run run = sim::simulate(circle(10.0, 2500.0, 2, "both"));
  // Lost frames inside a revolution and across a segment boundary, a saturated sample,
  // a NaN temperature.
  for (std::size_t k : {40000u, 40001u, 40002u, 61234u})
    run.frames.erase(run.frames.begin() + static_cast<std::ptrdiff_t>(k));
  for (std::size_t k = 40000; k < 40002; ++k) run.frames[k].flags |= dsp::frame_flag::gap_before;
  run.frames[50000].flags |= dsp::frame_flag::accel_saturated;
  run.frames[50010].temp_c[0] = kNaN;
  const dsp::Analysis whole = whole_trace(run);
  expect_same_result(run, whole, streamed(run));
  dsp::Run bare = sim::simulate(circle(10.0, 2500.0, 1, "ccw"));
  for (auto& f : bare.frames) f.trigger = 0;  // no marks, no M101: nothing to evaluate, the same way
  expect_same_result(bare, whole_trace(bare), streamed(bare));
}

TEST(AnalyzeStream, OtherProgramsAreEvaluatedOverTheirWholeTrace) {
  for (const auto& sc :
       {sim::step_scenario(), sim::positioning_scenario({0.0, 10.0, 20.0}, 2), sim::rectangle_scenario(20.0, 10.0)}) {
    const dsp::Run run = sim::simulate(sc);
    const dsp::Analysis whole = whole_trace(run);
    const dsp::Analysis s = streamed(run);
    EXPECT_EQ(s.measurement.decimation, 1u);
    expect_same_result(run, whole, s);
  }
}

// As eical analyze reads a run: from disk, twice, spills in files.
TEST(AnalyzeStream, ReadFromDiskAsEicalAnalyzeReadsIt) {
  const fs::path dir = fs::temp_directory_path() / ("eical-stream-test-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  sim::Scenario one_sensor = circle(10.0, 2500.0, 2, "both");
  struct Case {
    std::string name;
    dsp::Run run;
    bool gzip;
  };
  std::vector<Case> cases;
  cases.push_back({"plain", sim::simulate(circle(10.0, 2500.0, 2, "both")), false});
  cases.push_back({"gzip", sim::simulate(circle(10.0, 2500.0, 1, "cw")), true});
  {
    // The head's triplex empty in every row: an absent sensor, not a missing one.
    dsp::Run r = sim::simulate(one_sensor);
    r.meta.sensor_present[1] = false;
    cases.push_back({"one sensor", r, false});
  }
  {
    // The first row misses a field of the head: the reader assumes it absent until it has
    // read every row, then reads the run again.
    dsp::Run r = sim::simulate(circle(10.0, 2500.0, 1, "both"));
    r.frames.front().flags |= dsp::frame_flag::accel_missing | dsp::frame_flag::head_missing;
    cases.push_back({"first row", r, false});
  }
  for (auto& c : cases) {
    SCOPED_TRACE(c.name);
    const fs::path run_dir = dir / c.name;
    drivers::write_run(c.run, run_dir, {.gzip = c.gzip, .overwrite = true});
    const dsp::Run read = drivers::read_run(run_dir);
    const dsp::Analysis whole = whole_trace(read);
    for (const bool spill_trace : {false, true}) {  // the second pass from the file or from the spilled trace
      drivers::RunStream stream(run_dir);
      dsp::StreamOptions so;
      so.spills = drivers::file_spills(dir);
      so.spill_trace = so.spill_corrections = spill_trace;
      so.materialize_samples = 0;
      const dsp::Analysis s = drivers::analyze_stream(stream, with_uncertainty(), so);
      EXPECT_EQ(stream.header().meta.sensor_present[0], read.meta.sensor_present[0]);
      EXPECT_EQ(stream.header().meta.sensor_present[1], read.meta.sensor_present[1]);
      EXPECT_EQ(stream.header().frame_count(), read.frames.size());
      expect_same_result(read, whole, s);
    }
  }
  fs::remove_all(dir);
}

// The uncertainty of a circle evaluated as it streams is the whole trace's: its Monte
// Carlo reads every sample it needs as the trace goes by, however thinned the kept arrays;
// a run short enough is kept whole (materialize_samples) and gives the same.
TEST(AnalyzeStream, UncertaintyOfAStreamedCircleIsTheWholeTracesWhateverTheThinning) {
  const dsp::Run run = sim::simulate(circle(10.0, 2500.0, 2, "both"));
  const dsp::Analysis whole = whole_trace(run);
  ASSERT_FALSE(whole.uncertainty_k2.empty()) << whole.uncertainty_note;
  ASSERT_TRUE(whole.uncertainty_k2.count("circle.circular_deviation_G_um"));
  dsp::StoredFrames frames(run.frames);
  const dsp::Analysis kept_whole = dsp::analyze_stream(run, frames, with_uncertainty(), {});
  EXPECT_EQ(kept_whole.measurement.decimation, 1u);
  expect_same_result(run, whole, kept_whole);
  for (const std::size_t points : {std::size_t{50000000}, std::size_t{700}}) {
    const dsp::Analysis s = streamed(run, points);
    EXPECT_EQ(s.measurement.decimation > 1, points < whole.measurement.sample_index.size());
    EXPECT_EQ(s.uncertainty_k2, whole.uncertainty_k2) << "kept points " << points;
    EXPECT_EQ(s.uncertainty_note, whole.uncertainty_note);
    EXPECT_EQ(s.verdict, whole.verdict);
    EXPECT_EQ(s.verdict_reasons, whole.verdict_reasons);
  }
}

TEST(AnalyzeStream, BadInputNamesItsCause) {
  const fs::path dir = fs::temp_directory_path() / ("eical-stream-bad-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  drivers::write_run(sim::simulate(circle(10.0, 2500.0, 1, "ccw")), dir, {.gzip = false, .overwrite = true});
  {  // a row cut short in the middle of the file: the second reading meets it too
    std::ifstream is(dir / "samples.csv");
    std::string text((std::istreambuf_iterator<char>(is)), std::istreambuf_iterator<char>());
    const auto at = text.find('\n', text.size() / 2);
    text.insert(at, ",");
    std::ofstream(dir / "samples.csv") << text;
  }
  drivers::RunStream stream(dir);
  try {
    (void)drivers::analyze_stream(stream, {}, {drivers::file_spills(dir)});
    ADD_FAILURE() << "a malformed row went through";
  } catch (const dsp::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("samples.csv:"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("wrong number of fields"), std::string::npos) << e.what();
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace eical
