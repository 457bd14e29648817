// Channel health before the pipeline (issue 32): a simulated circle run with one channel
// damaged — stuck at 0, constant for a stretch, flat, clipped, missing for a span, an empty
// column, a PSD electrode stuck, cut at half — is found (code, channel, span) and gives no
// millimetres from a dead channel; healthy runs of several seeds and the sample runs give
// no finding.
#include "dsp/health/channel_health.hpp"
#include "drivers/import/imported_run.hpp"
#include "drivers/run_io/run_reader.hpp"
#include "drivers/run_io/run_writer.hpp"
#include "dsp/analysis/analyze_run.hpp"
#include "dsp/analysis/channel_findings.hpp"
#include "dsp/analysis/verdict.hpp"
#include "dsp/core/error.hpp"
#include "dsp/core/frame_fields.hpp"
#include "dsp/stream/analyze_stream.hpp"
#include "sim/scenario.hpp"
#include "sim/simulate.hpp"
#include "tests/support/sample_data.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace eical {
namespace {

namespace fs = std::filesystem;
using dsp::health::Fault;
using dsp::health::Finding;

constexpr int kTableAx = 0, kTableAy = 1, kHeadAz = 5, kPsd0I1 = 6;

const dsp::Run& circle_run() {
  static const dsp::Run run = [] {
    sim::Scenario sc = sim::circle_scenario(10.0, 2500.0, 1);
    sc.meta.psd = sim::psd_config_b(10.0);
    return sim::simulate(sc);
  }();
  return run;
}

dsp::AnalysisOptions fast() {
  dsp::AnalysisOptions o;
  o.uncertainty.enabled = false;  // the figures' presence is the point, not their U
  return o;
}

double t_of(const dsp::Run& run, std::size_t i) {
  return static_cast<double>(run.frames[i].sample_index - run.frames.front().sample_index) / run.fs_hz();
}

std::size_t frame_at(const dsp::Run& run, double t_s) { return static_cast<std::size_t>(t_s * run.fs_hz()); }

const Finding* find(const std::vector<Finding>& f, Fault fault, int channel) {
  for (const auto& x : f)
    if (x.fault == fault && x.channel == channel) return &x;
  return nullptr;
}

std::string all_flags(const dsp::Analysis& a) {
  std::string s;
  for (const auto& f : a.flags) s += flag_text(f) + "\n";
  return s;
}

using dsp::FlagCode;

// A flag of that code whose detail begins with `detail` (the counts and times the finding
// carries).
bool has_flag(const dsp::Analysis& a, FlagCode code, const std::string& detail = {}) {
  return std::any_of(a.flags.begin(), a.flags.end(),
                     [&](const dsp::Flag& f) { return f.code == code && f.detail.rfind(detail, 0) == 0; });
}

// The program's figures left unevaluated, with the reason.
bool has_program_null(const dsp::Analysis& a, const std::string& program, const std::string& why) {
  return std::any_of(a.flags.begin(), a.flags.end(), [&](const dsp::Flag& f) {
    return f.code == FlagCode::evaluation_failed && f.figure == program && f.detail == why;
  });
}

// Degraded because of the finding: the result says so, and the verdict names it among its
// reasons (a verdict without the figures' uncertainty is degraded anyway).
void expect_degraded_naming(const dsp::Analysis& a, const std::string& what) {
  EXPECT_TRUE(a.degraded);
  EXPECT_EQ(a.verdict, dsp::Verdict::degraded);
  std::string reasons;
  for (const auto& r : a.verdict_reasons) reasons += r + "\n";
  EXPECT_NE(reasons.find(what), std::string::npos) << reasons;
}

// The first time at which the set-point moves: the end of the rest window.
std::size_t first_motion(const dsp::Run& run) {
  for (std::size_t i = 1; i < run.frames.size(); ++i)
    if (run.frames[i].cmd_mm[0] != run.frames[i - 1].cmd_mm[0] ||
        run.frames[i].cmd_mm[1] != run.frames[i - 1].cmd_mm[1])
      return i;
  return run.frames.size();
}

// Both analyses, the whole run in memory and streamed (its circle evaluated as it goes by),
// reach the same conclusion about the channels.
void expect_same_in_stream(const dsp::Run& run, const dsp::Analysis& whole) {
  dsp::StoredFrames frames(run.frames);
  dsp::StreamOptions so;
  so.materialize_samples = 0;
  const dsp::Analysis s = dsp::analyze_stream(run, frames, fast(), so);
  EXPECT_EQ(s.flags, whole.flags);
  EXPECT_EQ(s.verdict, whole.verdict);
  EXPECT_EQ(s.circle.has_value(), whole.circle.has_value());
}

TEST(ChannelHealth, HealthyRunsOfSeveralSeedsHaveNoFinding) {
  for (std::uint64_t seed : {1u, 2u, 3u, 4u, 5u}) {
    SCOPED_TRACE(seed);
    sim::Scenario sc = sim::circle_scenario(10.0, 2500.0, 1, "ccw", seed);
    sc.meta.psd = sim::psd_config_b(10.0);
    const dsp::Run run = sim::simulate(sc);
    const auto f = dsp::health::check_channels(run);
    for (const auto& x : f)
      ADD_FAILURE() << dsp::health::fault_code(x.fault) << " " << dsp::health::channel_name(x.channel) << " "
                    << x.from_s << ".." << x.to_s << " s";
  }
  const dsp::Analysis a = dsp::analyze_run(circle_run(), fast());
  EXPECT_TRUE(a.circle.has_value());
  EXPECT_FALSE(has_flag(a, FlagCode::channel_untrusted)) << all_flags(a);
  EXPECT_FALSE(has_flag(a, FlagCode::channel_unused)) << all_flags(a);
  EXPECT_FALSE(has_flag(a, FlagCode::truncated)) << all_flags(a);
}

// The limits come from the data sheet: σ of an SF3000L axis at 10 kHz is about 41 counts
// (0.4 µg/√Hz · √fs · 1.23 V/g / 1.19 µV); a stuck stretch is a dozen samples of it.
TEST(ChannelHealth, LimitsFollowTheSensorsNoise) {
  const dsp::Run& run = circle_run();
  dsp::health::ChannelHealth h(run);
  EXPECT_NEAR(h.noise_counts(kTableAy), 0.4e-6 * 100.0 * 1.228 / 1.1920929e-6, 0.5);
  EXPECT_GT(h.stuck_samples(kTableAy), 5);
  EXPECT_LT(h.stuck_samples(kTableAy), 40);
  // A quieter sensor needs a longer constant stretch before it is stuck; the PSD (no noise
  // figure) the longest.
  dsp::Run quiet;
  quiet.meta = run.meta, quiet.channels = run.channels;
  quiet.meta.sensors[0].noise_ug_per_rthz = 0.01;
  dsp::health::ChannelHealth hq(quiet);
  EXPECT_GT(hq.stuck_samples(kTableAy), h.stuck_samples(kTableAy));
  EXPECT_GE(h.stuck_samples(kPsd0I1), hq.stuck_samples(kTableAy));
}

TEST(ChannelHealth, StuckAtZeroGivesNoMillimetres) {
  dsp::Run run = circle_run();
  for (auto& f : run.frames) f.accel_counts[kTableAy] = 0;
  const auto findings = dsp::health::check_channels(run);
  const Finding* s = find(findings, Fault::stuck, kTableAy);
  ASSERT_NE(s, nullptr);
  EXPECT_EQ(s->value, 0.0);
  EXPECT_DOUBLE_EQ(s->from_s, 0.0);
  EXPECT_DOUBLE_EQ(s->to_s, t_of(run, run.frames.size() - 1));
  EXPECT_EQ(s->samples, static_cast<std::int64_t>(run.frames.size()));
  EXPECT_EQ(find(findings, Fault::dead, kTableAy), nullptr);  // the stuck stretch covers the rest
  const dsp::Analysis a = dsp::analyze_run(run, fast());
  EXPECT_FALSE(a.circle.has_value());
  EXPECT_FALSE(a.diagnostics.has_value());
  EXPECT_TRUE(has_program_null(a, "circle", "null, not evaluated: machine Y not measured (table_ay stuck)"))
      << all_flags(a);
  EXPECT_TRUE(has_flag(a, FlagCode::channel_untrusted, "table_ay stuck at 0 counts from 0.000 s")) << all_flags(a);
  expect_degraded_naming(a, "table_ay stuck");
  expect_same_in_stream(run, a);
}

TEST(ChannelHealth, ConstantForAStretchIsStuckThere) {
  dsp::Run run = circle_run();
  const std::size_t from = frame_at(run, 1.0), to = frame_at(run, 1.5);
  for (std::size_t i = from; i <= to; ++i)
    run.frames[i].accel_counts[kTableAx] = run.frames[from].accel_counts[kTableAx];
  const auto findings = dsp::health::check_channels(run);
  ASSERT_EQ(findings.size(), 1u);
  const Finding* s = find(findings, Fault::stuck, kTableAx);
  ASSERT_NE(s, nullptr);
  // The stretch may start a sample early when noise repeated a value there.
  EXPECT_NEAR(s->from_s, 1.0, 2e-4);
  EXPECT_NEAR(s->to_s, 1.5, 2e-4);
  EXPECT_EQ(s->value, run.frames[from].accel_counts[kTableAx]);
  const dsp::Analysis a = dsp::analyze_run(run, fast());
  EXPECT_FALSE(a.circle.has_value());
  expect_degraded_naming(a, "channel: table_ax stuck");
}

TEST(ChannelHealth, FlatAtRestIsDead) {
  dsp::Run run = circle_run();
  // Toggling an LSB: never constant for long, but far quieter than the data sheet.
  for (std::size_t i = 0; i < run.frames.size(); ++i)
    run.frames[i].accel_counts[kTableAy] = 9600 + static_cast<std::int32_t>(i % 2);
  const auto findings = dsp::health::check_channels(run);
  ASSERT_EQ(findings.size(), 1u);
  const Finding* d = find(findings, Fault::dead, kTableAy);
  ASSERT_NE(d, nullptr);
  EXPECT_LT(d->value, 0.1);
  // The rest window: M101 (or the first sample) to the set-point's first motion.
  const std::size_t motion = first_motion(run);
  std::size_t m101 = 0;
  while (m101 < motion && run.frames[m101].trigger != dsp::trigger::program_start) ++m101;
  EXPECT_DOUBLE_EQ(d->from_s, t_of(run, m101 < motion ? m101 : 0));
  EXPECT_DOUBLE_EQ(d->to_s, t_of(run, motion - 1));
  const dsp::Analysis a = dsp::analyze_run(run, fast());
  EXPECT_FALSE(a.circle.has_value());
  EXPECT_TRUE(has_program_null(a, "circle", "null, not evaluated: machine Y not measured (table_ay dead)"))
      << all_flags(a);
}

TEST(ChannelHealth, ClippedSpanIsNamedAndDegrades) {
  dsp::Run run = circle_run();
  const double full = std::ldexp(1.0, run.meta.acquisition.adc_bits - 1);
  const std::size_t from = frame_at(run, 2.0), to = frame_at(run, 2.1);
  for (std::size_t i = from; i <= to; ++i) {
    run.frames[i].accel_counts[kTableAx] = static_cast<std::int32_t>(full - 1);
    run.frames[i].flags |= dsp::frame_flag::accel_saturated;
  }
  const auto findings = dsp::health::check_channels(run);
  ASSERT_EQ(findings.size(), 1u);  // clipped, not stuck as well
  const Finding* c = find(findings, Fault::clipped, kTableAx);
  ASSERT_NE(c, nullptr);
  EXPECT_DOUBLE_EQ(c->from_s, t_of(run, from));
  EXPECT_DOUBLE_EQ(c->to_s, t_of(run, to));
  EXPECT_EQ(c->samples, static_cast<std::int64_t>(to - from + 1));
  const dsp::Analysis a = dsp::analyze_run(run, fast());
  expect_degraded_naming(a, "channel: table_ax clipped");
  EXPECT_TRUE(
      has_flag(a, FlagCode::channel_untrusted, "table_ax clipped at the ADC's full scale from 2.000 s to 2.100 s"))
      << all_flags(a);
}

TEST(ChannelHealth, MissingSpanIsNamedAndDegrades) {
  dsp::Run run = circle_run();
  const std::size_t from = frame_at(run, 1.0), to = frame_at(run, 1.2);
  for (std::size_t i = from; i <= to; ++i)
    run.frames[i].flags |= dsp::frame_flag::accel_missing | dsp::frame_flag::table_missing |
                           dsp::frame_flag::accel_field_missing(kTableAx);
  const auto findings = dsp::health::check_channels(run);
  ASSERT_EQ(findings.size(), 1u);
  const Finding* m = find(findings, Fault::missing, kTableAx);
  ASSERT_NE(m, nullptr);
  EXPECT_DOUBLE_EQ(m->from_s, t_of(run, from));
  EXPECT_DOUBLE_EQ(m->to_s, t_of(run, to));
  EXPECT_EQ(m->samples, static_cast<std::int64_t>(to - from + 1));
  const dsp::Analysis a = dsp::analyze_run(run, fast());
  expect_degraded_naming(a, "channel: table_ax missing");
  EXPECT_TRUE(a.circle.has_value());  // the sensor held over the gap: degraded, not refused
  EXPECT_TRUE(has_flag(a, FlagCode::channel_untrusted, "table_ax missing from 1.000 s to 1.200 s")) << all_flags(a);
  expect_same_in_stream(run, a);
}

// An empty head_az: found. The circle in XY does not use machine Z, but the pipeline holds
// the whole head sensor while a field of it is missing — every sample here — so machine X
// and Y are not measured either: no figures, not millimetres from a held sensor.
TEST(ChannelHealth, EmptyColumnSpoilsItsSensor) {
  dsp::Run run = circle_run();
  for (auto& f : run.frames) {
    f.flags |=
        dsp::frame_flag::accel_missing | dsp::frame_flag::head_missing | dsp::frame_flag::accel_field_missing(kHeadAz);
    f.accel_counts[kHeadAz] = 0;
  }
  const auto findings = dsp::health::check_channels(run);
  ASSERT_EQ(findings.size(), 1u);
  const Finding* e = find(findings, Fault::empty, kHeadAz);
  ASSERT_NE(e, nullptr);
  EXPECT_EQ(e->samples, static_cast<std::int64_t>(run.frames.size()));
  const dsp::Analysis a = dsp::analyze_run(run, fast());
  expect_degraded_naming(a, "channel: head_az empty");
  EXPECT_TRUE(has_flag(a, FlagCode::channel_untrusted,
                       "head_az empty: not one sample in the run: the head sensor, held without it"))
      << all_flags(a);
  EXPECT_TRUE(has_program_null(a, "circle", "null, not evaluated: machine X, Y not measured (head_az empty)"))
      << all_flags(a);
  EXPECT_FALSE(a.circle.has_value());
  expect_same_in_stream(run, a);
}

// A step along X does not need the table's z axis: a stuck table_az is flagged, not fatal.
TEST(ChannelHealth, StuckChannelTheProgramDoesNotUseIsAWarning) {
  dsp::Run run = sim::simulate(sim::step_scenario(0.0, 20.0, 3250.0, 1));
  for (auto& f : run.frames) f.accel_counts[2] = 1000000;
  const dsp::Analysis a = dsp::analyze_run(run, fast());
  EXPECT_TRUE(has_flag(a, FlagCode::channel_unused, "table_az stuck at 1000000 counts")) << all_flags(a);
  EXPECT_TRUE(a.step.has_value());
  EXPECT_EQ(dsp::severity(FlagCode::channel_unused), dsp::FlagSeverity::warning);
  EXPECT_FALSE(dsp::any_critical(a.flags)) << all_flags(a);
}

// Through the file: an empty column keeps its sensor present (run-format.md: a sensor is
// absent only when every field of its triplex is empty) and names the field.
TEST(ChannelHealth, EmptyColumnInTheFileIsNotAnAbsentSensor) {
  const fs::path dir = fs::temp_directory_path() / "eical-health-empty";
  fs::remove_all(dir);
  dsp::Run run = circle_run();
  run.frames.resize(2000);
  for (auto& f : run.frames)
    f.flags |=
        dsp::frame_flag::accel_missing | dsp::frame_flag::head_missing | dsp::frame_flag::accel_field_missing(kHeadAz);
  drivers::write_run(run, dir, {});
  const dsp::Run back = drivers::read_run(dir);
  EXPECT_TRUE(back.meta.sensor_present[1]);
  EXPECT_EQ(back.frames[7].flags & dsp::frame_flag::sensor_fields_missing(1),
            dsp::frame_flag::accel_field_missing(kHeadAz));
  EXPECT_EQ(back.frames[7].accel_counts[3], run.frames[7].accel_counts[3]);
  const auto findings = dsp::health::check_channels(back);
  ASSERT_NE(find(findings, Fault::empty, kHeadAz), nullptr);
  fs::remove_all(dir);
}

// NaN in an accelerometer column is refused by the reader, naming file, line and column.
TEST(ChannelHealth, NanInAColumnIsRefusedByName) {
  const fs::path dir = fs::temp_directory_path() / "eical-health-nan";
  fs::remove_all(dir);
  dsp::Run run = circle_run();
  run.frames.resize(100);
  drivers::write_run(run, dir, {});
  std::ifstream is(dir / "samples.csv");
  std::stringstream out;
  std::string line;
  std::getline(is, line);
  out << line << "\n";
  while (std::getline(is, line)) {
    const auto a = line.find(',') + 1, b = line.find(',', a) + 1, c = line.find(',', b);
    out << line.substr(0, b) << "nan" << line.substr(c) << "\n";  // table_ay
  }
  is.close();
  std::ofstream(dir / "samples.csv") << out.str();
  try {
    (void)drivers::read_run(dir);
    ADD_FAILURE() << "a NaN column was read";
  } catch (const dsp::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("samples.csv:2: column 'table_ay'"), std::string::npos) << e.what();
  }
  fs::remove_all(dir);
}

TEST(ChannelHealth, StuckPsdElectrodeDegrades) {
  dsp::Run run = circle_run();
  ASSERT_GE(run.channels.psd_count, 1);
  for (auto& f : run.frames) f.psd_counts[0] = 1234;
  const auto findings = dsp::health::check_channels(run);
  ASSERT_EQ(findings.size(), 1u);
  ASSERT_NE(find(findings, Fault::stuck, kPsd0I1), nullptr);
  const dsp::Analysis a = dsp::analyze_run(run, fast());
  expect_degraded_naming(a, "channel: psd0_i1 stuck");
  EXPECT_TRUE(has_flag(a, FlagCode::channel_untrusted, "psd0_i1 stuck at 1234 counts")) << all_flags(a);
}

TEST(ChannelHealth, RecordingCutAtHalfIsTruncated) {
  dsp::Run run = circle_run();
  run.frames.resize(run.frames.size() / 2);
  const auto findings = dsp::health::check_channels(run);
  ASSERT_EQ(findings.size(), 1u);
  const Finding* t = find(findings, Fault::truncated, -1);
  ASSERT_NE(t, nullptr);
  EXPECT_TRUE(t->set_point_moving);
  EXPECT_DOUBLE_EQ(t->to_s, t_of(run, run.frames.size() - 1));
  const dsp::Analysis a = dsp::analyze_run(run, fast());
  expect_degraded_naming(a, "truncated: the recording ends at");
  EXPECT_TRUE(has_flag(a, FlagCode::truncated)) << all_flags(a);
  expect_same_in_stream(run, a);
  // The whole run's end trigger is there: not truncated.
  EXPECT_EQ(find(dsp::health::check_channels(circle_run()), Fault::truncated, -1), nullptr);
}

// The program's axes: which channels a circle in XY needs with the sensors mounted as given.
TEST(ChannelHealth, ProgramAxesFollowTheMounting) {
  dsp::RunMeta meta = circle_run().meta;
  EXPECT_EQ(dsp::program_axes(meta.program), 3u);
  EXPECT_EQ(dsp::channel_axes(meta, kTableAy), 2u);
  EXPECT_EQ(dsp::channel_axes(meta, kHeadAz), 4u);
  meta.sensors[1].to_machine << 0, 1, 0, -1, 0, 0, 0, 0, 1;  // head turned 90° about Z
  EXPECT_EQ(dsp::channel_axes(meta, 3), 2u);                 // its axis 1 measures machine Y
  meta.program.kind = eical::dsp::ProgramKind::step, meta.program.axis = "z";
  EXPECT_EQ(dsp::program_axes(meta.program), 4u);
}

// The sample runs (an independent simulator's, tests/data/README.md): no false finding.
TEST(ChannelHealth, SampleRunsHaveNoFinding) {
  int runs = 0;
  for (const fs::path& dir : test::all_runs()) {
    SCOPED_TRACE(dir.string());
    const dsp::Run run = drivers::read_run(dir);
    for (const auto& x : dsp::health::check_channels(run))
      ADD_FAILURE() << dsp::health::fault_code(x.fault) << " " << dsp::health::channel_name(x.channel) << " "
                    << x.from_s << ".." << x.to_s << " s";
    ++runs;
  }
  EXPECT_GE(runs, static_cast<int>(test::committed_runs().size()));
}

// Real ADXL345 captures (tests/data/real: 3200 Hz, 4 mg steps, moving), as
// `eical import` would set them up (1 µg a count, the chip's data sheet), without the
// importer's resampling (its exact values repeat the most): no finding. Their counts come in
// steps of the chip's LSB, where a few equal samples in a row are common (up to 9 here).
TEST(ChannelHealth, RealMemsCapturesHaveNoFinding) {
  const fs::path dir = test::committed_data() / "real" / "3dp-accelerometer_host-api";
  int captures = 0;
  for (const auto& e : fs::directory_iterator(dir)) {
    if (e.path().extension() != ".tsv") continue;
    SCOPED_TRACE(e.path().filename().string());
    dsp::Run run;
    run.meta.acquisition.fs_hz = 3200.0;
    run.meta.acquisition.adc_bits = 32;
    run.meta.acquisition.adc_lsb_volt = 1.0 / drivers::kImportCountsPerG;
    drivers::ImportSetup setup;
    run.meta.sensors[0] = run.meta.sensors[1] = drivers::import_sensor_spec(setup, 3200.0);
    run.meta.sensor_present[0] = false;
    std::ifstream is(e.path());
    std::string line;
    while (std::getline(is, line)) {
      if (line.empty() || !std::isdigit(static_cast<unsigned char>(line[0]))) continue;  // header, comment
      std::istringstream fields(line);
      std::string seq, sample;
      double mg[3] = {0.0, 0.0, 0.0};
      fields >> seq >> sample >> mg[0] >> mg[1] >> mg[2];
      dsp::Frame f;
      f.sample_index = static_cast<std::int64_t>(run.frames.size());
      for (int a = 0; a < 3; ++a) f.accel_counts[3 + a] = static_cast<std::int32_t>(std::lround(mg[a] * 1000.0));
      run.frames.push_back(f);
    }
    ASSERT_GT(run.frames.size(), 1000u);
    run.frames.front().trigger = dsp::trigger::program_start;
    run.frames.back().trigger = dsp::trigger::program_end;
    for (const auto& x : dsp::health::check_channels(run))
      ADD_FAILURE() << dsp::health::fault_code(x.fault) << " " << dsp::health::channel_name(x.channel) << " "
                    << x.from_s << ".." << x.to_s << " s";
    // The same data read in single counts would be stuck: the resolution is what saves it.
    dsp::health::ChannelHealth h(run);
    EXPECT_LT(h.stuck_samples(3), 9);
    ++captures;
  }
  EXPECT_EQ(captures, 6);
}

}  // namespace
}  // namespace eical
