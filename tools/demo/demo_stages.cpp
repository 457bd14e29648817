#include "tools/demo/demo_stages.hpp"

#include "drivers/run_io/run_writer.hpp"
#include "drivers/source/sim_source.hpp"
#include "dsp/analysis/figures.hpp"
#include "dsp/identify/sensor_identification.hpp"
#include "dsp/pipeline/pipeline.hpp"
#include "dsp/session/measurement_session.hpp"
#include "sim/simulate.hpp"

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace eical::tools::demo {
namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

constexpr const char* kG = "circle.circular_deviation_G_um";

double scalar(const std::map<std::string, std::vector<double>>& m, const char* key) {
  const auto it = m.find(key);
  return it != m.end() && it->second.size() == 1 ? it->second[0] : std::nan("");
}

}  // namespace

DemoMachine demo_machine(std::uint64_t seed, const DemoTest& test) {
  DemoMachine m;
  plan::TestProgram& p = m.program;
  p.kind = dsp::ProgramKind::circle, p.direction = "both";
  p.radius_mm = test.radius_mm, p.feed_mm_min = test.feed_mm_min, p.repeats = test.repeats;
  p.psd = plan::strips_for(p, test.strips, test.facing);  // 2 along: configuration B
  p.identified = true;
  m.circle = plan::scenario_on_drawn_machine(p, seed);
  // What a circular test is for: a backlash on x and an out-of-square xy, on top of the
  // drawn machine's small errors.
  m.circle.machine.backlash_um[0] = 3.0;
  m.circle.machine.squareness_urad[0] = 25.0;
  m.identification = plan::identification_on_machine(p, m.circle, seed);
  return m;
}

OnSiteIdentification identify_on_site(const DemoMachine& m, const std::filesystem::path& out) {
  const auto t0 = Clock::now();
  OnSiteIdentification r;
  const dsp::Run run = sim::simulate(m.identification);
  r.run_dir = out / "identification";
  drivers::write_run(run, r.run_dir, {.gzip = false, .overwrite = true});
  const dsp::identify::Identification id = dsp::identify::identify_sensors(run);
  r.calibration = drivers::calibration_from(id, run.meta.id);
  r.file = out / "calibration.toml";
  drivers::write_sensor_calibration(r.calibration, r.file);
  r.seconds = seconds_since(t0);
  return r;
}

RecordedTest record_through_daemon_path(const sim::Scenario& sc, bool realtime) {
  const auto t0 = Clock::now();
  drivers::SimSource source(
      sc, {.pacing = realtime ? drivers::Pacing::realtime : drivers::Pacing::free_running, .keep_truth = true});
  source.open();
  const dsp::RunMeta& meta = source.meta();
  drivers::FrameRing ring(1 << 16);
  dsp::SessionConfig scfg;
  scfg.fs_hz = meta.acquisition.fs_hz;
  scfg.max_measurement_s = 120.0;
  dsp::MeasurementSession session(scfg);
  dsp::Pipeline live(dsp::pipeline_config(meta, static_cast<std::size_t>(scfg.max_measurement_s * scfg.fs_hz)));
  std::atomic<bool> stop{false};
  RecordedTest r;
  r.stats = drivers::pump(
      source, ring,
      [&](const dsp::Frame& f) {
        session.on_frame(f);
        if (session.state().state() == dsp::State::measuring || f.trigger == dsp::trigger::program_end) live.step(f);
      },
      stop);
  if (!r.stats.source_error.empty()) throw std::runtime_error(r.stats.source_error);
  std::vector<dsp::Frame> frames;
  frames.reserve(session.recorder_capacity());
  if (!session.take(frames))
    throw std::runtime_error("the simulated program did not complete a measurement (M101..M103); state " +
                             std::string(dsp::to_string(session.state().state())));
  session.evaluation_done();
  r.frames_lost = session.counters().frames_lost;
  r.run.meta = meta;
  r.run.channels = source.program_run()->channels;
  r.run.truth_toml = source.program_run()->truth_toml;
  r.run.frames = std::move(frames);
  const std::vector<Eigen::Vector3d>& truth = source.true_rel_mm();  // by the program pass' sample index
  r.truth_mm.reserve(r.run.frames.size());
  for (const dsp::Frame& f : r.run.frames) {
    const auto i = static_cast<std::size_t>(f.sample_index);
    r.truth_mm.push_back(i < truth.size() ? truth[i] : Eigen::Vector3d::Constant(std::nan("")));
  }
  r.seconds = seconds_since(t0);
  return r;
}

dsp::Analysis analyze_with(const dsp::Run& run, const drivers::SensorCalibration& cal) {
  dsp::Run calibrated = run;  // the recording keeps the data sheet; the analysis the calibration
  dsp::AnalysisOptions opt;
  drivers::apply_calibration(cal, calibrated.meta, opt);
  return dsp::analyze_run(calibrated, opt);
}

std::string headline_text(const dsp::Analysis& a, const std::vector<dsp::FigureValue>& truth) {
  std::string o;
  char b[400];
  std::snprintf(b, sizeof b, "  verdict %s\n", dsp::verdict_name(a.verdict));
  o += b;
  if (!a.circle) return o + "  (no circle evaluated: see the flags)\n";
  const double g = a.circle->circular_deviation_G_um, u = scalar(a.uncertainty_k2, kG);
  const double bound = scalar(a.noise_bound_k2, kG);
  std::snprintf(b, sizeof b, "  circular deviation G = %.2f ± %.2f µm (U, k = 2)", g, u);
  o += b;
  if (std::isfinite(bound) && bound > 0.0) {
    std::snprintf(b, sizeof b, "; noise bound %.2f µm, U/bound %.2f", bound, u / bound);
    o += b;
  }
  o += "\n";
  for (const char* key : {"circle.averaged_revolution_G_ccw_um", "circle.averaged_revolution_G_cw_um"}) {
    const auto figs = dsp::figures_of(a);
    const dsp::FigureValue* f = dsp::find_figure(figs, key);
    const double uk = scalar(a.uncertainty_k2, key), bk = scalar(a.noise_bound_k2, key);
    if (!f || f->values.size() != 1) continue;
    std::snprintf(b, sizeof b, "  G of the averaged revolution, %s = %.2f ± %.2f µm (noise bound %.2f µm)",
                  std::string(key).find("_cw_") != std::string::npos ? "cw" : "ccw", f->values[0], uk, bk);
    o += b;
    if (const dsp::FigureValue* t = dsp::find_figure(truth, key); t && t->values.size() == 1) {
      std::snprintf(b, sizeof b, "; truth %.2f µm, error %+.2f µm", t->values[0], f->values[0] - t->values[0]);
      o += b;
    }
    o += "\n";
  }
  if (const dsp::FigureValue* t = dsp::find_figure(truth, kG); t && t->values.size() == 1) {
    const double tg = t->values[0];
    std::snprintf(b, sizeof b, "  the simulator's truth G = %.2f µm: error %+.2f µm, %s U\n", tg, g - tg,
                  std::abs(g - tg) <= u ? "within" : "OUTSIDE");
    o += b;
  }
  return o;
}

dsp::Analysis beyond_the_instrument(std::uint64_t seed) {
  const dsp::Run run = sim::simulate(sim::circle_scenario(150.0, 4000.0, 1, "ccw", seed));
  return dsp::analyze_run(run);
}

}  // namespace eical::tools::demo
