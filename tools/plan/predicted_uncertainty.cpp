#include "tools/plan/predicted_uncertainty.hpp"

#include "drivers/exec/thread_for.hpp"
#include "dsp/analysis/verdict.hpp"
#include "dsp/core/axes.hpp"
#include "dsp/core/error.hpp"
#include "dsp/core/frame.hpp"
#include "dsp/identify/sensor_identification.hpp"
#include "dsp/stream/analyze_stream.hpp"
#include "sim/hidden/hidden_effects.hpp"
#include "sim/nc/envelope_check.hpp"
#include "sim/simulate.hpp"
#include "tools/figure_text.hpp"
#include "tools/plan/identification_plan.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <random>

namespace eical::tools::plan {

std::vector<TestProgram> geometric_variants(const TestProgram& p);

namespace {

std::string g(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%g", v);
  return b;
}

// The internal grid of a prediction's simulation: ten steps per period of the sensing
// element's resonance, at least the DAQ's rate. The prediction's machine is ideal and its
// sensors are the data sheet's, so nothing above the DAQ's band is there to alias. No
// predicted U moved by more than 0.1 % between this grid and the simulator's usual 100 kHz
// (R50 F2000 both, 100 draws, grid at 1, 2, 4 and 10 times the DAQ's rate); the 100 kHz
// grid took 150 MB more.
int prediction_oversample(const sim::Scenario& sc) {
  double f0_hz = 0.0;
  for (const auto& t : sc.truth) f0_hz = std::max(f0_hz, t.spec.f0_hz);
  return std::max(1, static_cast<int>(std::ceil(10.0 * f0_hz / sc.meta.acquisition.fs_hz)));
}

// A predicted run analysed as eical analyze reads a recording: streamed, so that the
// memory does not grow with the variant's length.
dsp::Analysis analyze_prediction(const dsp::Run& run, const dsp::AnalysisOptions& o) {
  dsp::StoredFrames frames(run.frames);
  dsp::StreamOptions so;
  so.materialize_samples = 0;
  return dsp::analyze_stream(run, frames, o, so);
}

// The largest feed a variant may ask for: 20 m/min and 2 m/s² of centripetal acceleration.
double feed_cap(const TestProgram& p) {
  double f = 20000.0;
  if (p.kind == dsp::ProgramKind::circle) f = std::min(f, std::sqrt(2000.0 * p.radius_mm) * 60.0);
  return f;
}

}  // namespace

std::string describe(const TestProgram& p) {
  std::string s;
  if (p.kind == dsp::ProgramKind::circle) {
    s = "circle R" + g(p.radius_mm) + " F" + g(p.feed_mm_min) + " " + p.direction + " x" + std::to_string(p.repeats) +
        " in " + p.plane;
    if (p.arc_deg < 360.0) s += ", " + g(p.arc_deg) + " deg arc";
  } else if (p.kind == dsp::ProgramKind::positioning) {
    s = "positioning x " + g(p.targets_mm.front()) + ".." + g(p.targets_mm.back()) + " mm, " +
        std::to_string(p.targets_mm.size()) + " targets, " + std::to_string(p.runs) + " runs, F" + g(p.feed_mm_min);
  } else if (p.kind == dsp::ProgramKind::step) {
    s = "step x " + g(p.from_mm) + " -> " + g(p.to_mm) + " mm, " + std::to_string(p.runs) + " pairs, F" +
        g(p.feed_mm_min);
  } else {
    s = "rectangle " + g(p.size_mm[0]) + " x " + g(p.size_mm[1]) + " mm in " + p.plane + ", F" + g(p.feed_mm_min);
  }
  s += p.psd.empty() ? ", no PSD strips"
                     : ", " + std::to_string(p.psd.size()) + " PSD strip" + (p.psd.size() > 1 ? "s" : "");
  if (p.kind == dsp::ProgramKind::circle && sim::ring_facing(p.psd) == sim::StripFacing::across_path)
    s += " turned radial";
  if (p.identified) s += ", sensors identified on site first (eical gen-nc identify, eical identify)";
  return s;
}

std::vector<dsp::PsdSpec> strips_at_both_ends(const TestProgram& p) {
  // The ends of the x travel the test moves over: one place says where that is.
  std::optional<sim::gcode::AxisTravel> travel_mm[2];
  test_travel(p, travel_mm);
  if ((p.kind != dsp::ProgramKind::step && p.kind != dsp::ProgramKind::positioning) || !travel_mm[0]) return {};
  std::vector<dsp::PsdSpec> out(2);
  out[0].measures = out[1].measures = "x";
  out[0].center_mm[0] = travel_mm[0]->lo_mm, out[1].center_mm[0] = travel_mm[0]->hi_mm;
  return out;
}

std::vector<dsp::PsdSpec> strips_identification_can_cross(const TestProgram& p) {
  std::optional<sim::gcode::AxisTravel> travel_mm[2];
  test_travel(p, travel_mm);
  std::vector<dsp::PsdSpec> out = p.psd;
  // A circle crosses each strip where it is: the identification reaches it there
  // (identification_plan runs the swing on beyond the circle where it must).
  if (p.kind == dsp::ProgramKind::circle) return out;
  for (auto& s : out) {
    const int along = dsp::axis_index(s.measures);
    if (along < 0 || along > 1 || !travel_mm[along]) continue;
    const auto& t = *travel_mm[along];
    // One strip length inside each end: a swing that stays inside the travel crosses it
    // whole (gen-nc identify refuses one it cannot cross); on a travel too short for that,
    // the middle.
    const double inset_mm = s.length_mm;
    s.center_mm[along] = t.hi_mm - t.lo_mm >= 2.0 * inset_mm
                             ? std::clamp(s.center_mm[along], t.lo_mm + inset_mm, t.hi_mm - inset_mm)
                             : 0.5 * (t.lo_mm + t.hi_mm);
  }
  return out;
}

std::vector<dsp::PsdSpec> strips_for(const TestProgram& p) {
  if (p.kind == dsp::ProgramKind::circle) return sim::psd_config_b(p.radius_mm);
  dsp::PsdSpec x;
  x.measures = "x";
  if (p.kind == dsp::ProgramKind::step) {
    x.center_mm[0] = 0.5 * (p.from_mm + p.to_mm);
    return {x};
  }
  if (p.kind == dsp::ProgramKind::positioning) {
    x.center_mm[0] = 0.5 * (p.targets_mm.front() + p.targets_mm.back());
    return {x};
  }
  dsp::PsdSpec y;  // rectangle from the origin: the middle of its first two sides
  y.measures = "y";
  x.center_mm[0] = 0.5 * p.size_mm[0], x.center_mm[1] = 0.0;
  y.center_mm[0] = p.size_mm[0], y.center_mm[1] = 0.5 * p.size_mm[1];
  return {x, y};
}

std::vector<dsp::PsdSpec> strips_for(const TestProgram& p, int count, sim::StripFacing facing) {
  if (count == 0) return {};
  if (p.kind == dsp::ProgramKind::circle) return sim::psd_ring(p.radius_mm, count, facing);
  if (count == 2 && facing == sim::StripFacing::along_path) return strips_for(p);
  throw dsp::InputError("plan: " + std::to_string(count) + " strips are a circle's layout; a " +
                        std::string(dsp::program_kind_name(p.kind)) + " test takes B (" +
                        std::to_string(strips_for(p).size()) + ") or strips given one by one");
}

TestProgram program_of(const dsp::RunMeta& meta) {
  TestProgram p;
  const auto& q = meta.program;
  p.kind = q.kind;
  p.plane = q.plane, p.direction = q.direction;
  p.radius_mm = q.radius_mm, p.feed_mm_min = q.feed_mm_min, p.arc_deg = q.arc_deg;
  p.repeats = std::max(1, q.repeats);
  if (!q.targets_mm.empty()) p.targets_mm = q.targets_mm;
  p.runs = std::max(1, q.runs);
  if (q.kind == dsp::ProgramKind::step && q.targets_mm.size() >= 2)
    p.from_mm = q.targets_mm[0], p.to_mm = q.targets_mm[1];
  p.size_mm[0] = q.size_mm[0] > 0.0 ? q.size_mm[0] : 50.0, p.size_mm[1] = q.size_mm[1] > 0.0 ? q.size_mm[1] : 50.0;
  p.psd = meta.psd;
  p.noise_ug_per_rthz =
      std::hypot(meta.sensors[0].noise_ug_per_rthz, meta.sensors[1].noise_ug_per_rthz) / std::sqrt(2.0);
  p.fs_hz = meta.acquisition.fs_hz;
  return p;
}

sim::Scenario scenario_of(const TestProgram& p, std::uint64_t seed) {
  sim::Scenario sc;
  if (p.kind == dsp::ProgramKind::circle) {
    sc = sim::circle_scenario(p.radius_mm, p.feed_mm_min, p.repeats, p.direction, seed);
    sc.meta.program.plane = p.plane;
    sc.meta.program.arc_deg = p.arc_deg;
  } else if (p.kind == dsp::ProgramKind::step) {
    sc = sim::step_scenario(p.from_mm, p.to_mm, p.feed_mm_min, p.runs, seed);
  } else if (p.kind == dsp::ProgramKind::positioning) {
    sc = sim::positioning_scenario(p.targets_mm, p.runs, p.feed_mm_min, seed);
  } else if (p.kind == dsp::ProgramKind::rectangle) {
    sc = sim::rectangle_scenario(p.size_mm[0], p.size_mm[1], p.feed_mm_min, p.plane, std::max(1, p.repeats), seed);
  } else {
    throw dsp::InputError("plan: program kind '" + std::string(dsp::program_kind_name(p.kind)) +
                          "' (circle, positioning, step or rectangle)");
  }
  sc.meta.psd = p.psd;
  sc.meta.acquisition.fs_hz = p.fs_hz;
  for (auto& t : sc.truth) t.spec.noise_ug_per_rthz = p.noise_ug_per_rthz;
  for (auto& s : sc.meta.sensors) s.noise_ug_per_rthz = p.noise_ug_per_rthz;
  return sc;
}

sim::Scenario scenario_on_drawn_machine(const TestProgram& p, std::uint64_t seed) {
  sim::Scenario sc = scenario_of(p, seed);
  const sim::Scenario bg = sim::hidden_effect_scenario(
      {}, p.kind == dsp::ProgramKind::circle ? dsp::ProgramKind::circle : dsp::ProgramKind::step, seed);
  sc.meta.site = bg.meta.site;
  sc.meta.machine = bg.meta.machine;
  for (int s = 0; s < 2; ++s) {
    sc.truth[s] = bg.truth[s];
    sc.truth[s].spec.noise_ug_per_rthz =
        p.noise_ug_per_rthz * bg.truth[s].spec.noise_ug_per_rthz / bg.meta.sensors[s].noise_ug_per_rthz;
  }
  sc.daq = bg.daq;
  sc.machine = bg.machine;
  sc.coriolis = bg.coriolis;
  sc.psd = drawn_strips(sc.meta.psd, seed);
  return sc;
}

std::vector<sim::PsdTruth> drawn_strips(const std::vector<dsp::PsdSpec>& psd, std::uint64_t seed) {
  std::vector<sim::PsdTruth> out;
  const double bound = dsp::DatasheetTolerance{}.psd_nonlinearity;
  for (const dsp::PsdSpec& s : psd) {
    // Keyed by the strip's place: the identification and the test cross the same strip.
    const std::string key = s.measures + ":" + std::to_string(std::llround(s.center_mm[0] * 1000.0)) + "," +
                            std::to_string(std::llround(s.center_mm[1] * 1000.0));
    std::mt19937_64 rng(seed ^ std::hash<std::string>{}(key));
    sim::PsdTruth t;
    t.nonlinearity = std::uniform_real_distribution<double>(-bound, bound)(rng);
    out.push_back(t);
  }
  return out;
}

sim::Scenario identification_scenario(const TestProgram& p, std::uint64_t seed) {
  sim::Scenario sc = sim::identify_scenario(identification_plan(p), seed);
  sc.meta.acquisition.fs_hz = p.fs_hz;
  for (auto& t : sc.truth) t.spec.noise_ug_per_rthz = p.noise_ug_per_rthz;
  for (auto& s : sc.meta.sensors) s.noise_ug_per_rthz = p.noise_ug_per_rthz;
  return sc;
}

sim::Scenario identification_on_machine(const TestProgram& p, const sim::Scenario& machine, std::uint64_t seed) {
  sim::Scenario id = identification_scenario(p, seed);
  id.meta.site = machine.meta.site, id.meta.machine = machine.meta.machine;
  for (int s = 0; s < 2; ++s) id.truth[s] = machine.truth[s];
  id.daq = machine.daq, id.machine = machine.machine, id.coriolis = machine.coriolis;
  id.psd = drawn_strips(id.meta.psd, seed);  // the machine's strips, the same nonlinearity
  return id;
}

dsp::SensorModelCovariance typical_identification(const TestProgram& p) {
  sim::Scenario sc = identification_scenario(p, 1);
  // On the prediction's grid too. What one simulated identification leaves is one draw of
  // it: the R10 variant's predicted U(G) after it was 6.31, 6.36, 6.59, 7.47 and 6.06 µm
  // with the grid at 1, 2, 5, 10 and 20 times the DAQ's rate, no trend with the grid.
  sc.oversample = prediction_oversample(sc);
  dsp::identify::IdentifyOptions o;
  o.compare_with_datasheet = false;
  return dsp::identify::identify_sensors(sim::simulate(sc), o).covariance;
}

double duration_s(const dsp::Run& run) {
  return run.frames.empty()
             ? 0.0
             : static_cast<double>(run.frames.back().sample_index - run.frames.front().sample_index) / run.fs_hz();
}

Prediction predict(const TestProgram& p, std::uint64_t seed, int draws,
                   const std::optional<dsp::SensorModelCovariance>& identified, const std::optional<Screen>& screen) {
  sim::Scenario sc = scenario_of(p, seed);
  sc.oversample = prediction_oversample(sc);
  const dsp::Run run = sim::simulate(sc);
  dsp::AnalysisOptions o;
  o.uncertainty.draws = draws;
  o.parallel = drivers::thread_for();
  const dsp::ResolutionLimit* lim = dsp::resolution_limit(p.kind);
  const double limit = lim ? p.resolve_um.value_or(lim->limit) : 0.0;
  if (screen && lim) o.uncertainty.stop_above = {lim->limited, screen->margin * limit, screen->draws};
  if (p.identified) {
    o.model_covariance = identified ? *identified : typical_identification(p);
    o.sensor_model = "psd";
  }
  const dsp::Analysis a = analyze_prediction(run, o);
  Prediction r;
  r.program = p;
  r.duration_s = duration_s(run);
  for (const auto& [k, u] : a.uncertainty_k2)
    if (u.size() == 1 && std::isfinite(u[0])) r.u_k2[k] = u[0];
  if (lim) {
    r.headline = lim->headline, r.limited = lim->limited, r.limit = limit;
    const auto it = r.u_k2.find(lim->limited);
    r.limited_u = it != r.u_k2.end() ? it->second : std::numeric_limits<double>::quiet_NaN();
    r.measurable = it != r.u_k2.end() && it->second <= limit;
  }
  return r;
}

std::vector<TestProgram> variants(const TestProgram& p) {
  std::vector<TestProgram> v = geometric_variants(p);
  // Identified: the identification crosses the test's strips, so a strip on a travel's end
  // moves one strip length inside it (the plan prints where each goes).
  auto identified = [](TestProgram t) {
    t.identified = true;
    t.psd = strips_identification_can_cross(t);
    return t;
  };
  if (p.identified) {
    for (auto& t : v) t = identified(t);
    return v;
  }
  std::vector<TestProgram> with_id{identified(p)};
  for (const TestProgram& t : v) with_id.push_back(identified(t));
  v.insert(v.end(), with_id.begin(), with_id.end());
  return v;
}

std::vector<TestProgram> geometric_variants(const TestProgram& p) {
  std::vector<TestProgram> v;
  TestProgram s = p;
  if (s.psd.empty()) {
    s.psd = strips_for(s);
    v.push_back(s);
  }
  if ((p.kind == dsp::ProgramKind::positioning || p.kind == dsp::ProgramKind::step) && s.psd.size() < 2) {
    // A strip at each end of the travel: the position is held at both ends of every run,
    // where a single strip at mid travel leaves the ends to the integration.
    TestProgram ends = s;
    ends.psd = strips_at_both_ends(s);
    if (!ends.psd.empty()) v.push_back(ends);
  }
  const double cap = feed_cap(s);
  for (double f : {2.0, 4.0}) {
    TestProgram t = s;
    t.feed_mm_min = std::min(cap, s.feed_mm_min * f);
    if (t.feed_mm_min > s.feed_mm_min * 1.2) v.push_back(t);
  }
  if (p.kind == dsp::ProgramKind::circle) {
    // More strips about the same circle: each crossing fixes the position once more a
    // revolution, so the integration's error grows over a shorter arc. Four stay along the
    // path (the spot runs along each for millimetres); sixteen are turned radial, each a
    // reading of the radius (bench_u_chart: R50 F4000 U(G) 1.8 µm against 3.3 along).
    for (const auto& [n, facing] :
         {std::pair{4, sim::StripFacing::along_path}, std::pair{dsp::kMaxPsd, sim::StripFacing::across_path}}) {
      if (static_cast<int>(s.psd.size()) >= n) continue;
      TestProgram t = s;
      t.psd = strips_for(t, n, facing);
      v.push_back(t);
    }
  }
  if (p.kind == dsp::ProgramKind::circle) {
    for (double r : {p.radius_mm / 3.0, 10.0}) {
      TestProgram t = s;
      t.radius_mm = std::max(10.0, std::round(r));
      if (t.radius_mm >= p.radius_mm) continue;
      t.feed_mm_min = std::min(s.feed_mm_min, feed_cap(t));
      if (r == 10.0) t.feed_mm_min = 2500.0, t.repeats = std::min(t.repeats, 5);  // the thesis' circular test
      t.psd = strips_for(t);
      v.push_back(t);
    }
  } else if (p.kind == dsp::ProgramKind::step || p.kind == dsp::ProgramKind::positioning) {
    TestProgram t = s;
    if (p.kind == dsp::ProgramKind::step)
      t.to_mm = t.from_mm + 0.5 * (t.to_mm - t.from_mm);
    else
      for (auto& x : t.targets_mm) x = t.targets_mm.front() + 0.5 * (x - t.targets_mm.front());
    t.psd = strips_for(t);
    v.push_back(t);
  } else if (p.kind == dsp::ProgramKind::rectangle) {
    TestProgram t = s;
    t.size_mm[0] *= 0.5, t.size_mm[1] *= 0.5;
    t.psd = strips_for(t);
    v.push_back(t);
  }
  return v;
}

std::optional<std::string> outside_envelope(const TestProgram& p, const dsp::WorkEnvelope& envelope) {
  const auto x = sim::nc::envelope_excess(*sim::scenario_set_point(scenario_of(p, 1)), envelope);
  if (!x) return std::nullopt;
  return sim::nc::describe(*x, envelope);
}

double program_duration_s(const TestProgram& p) { return sim::scenario_set_point(scenario_of(p, 1))->duration_s(); }

namespace {

double rough_duration_s(const TestProgram& t) {
  double path_mm = 0.0;
  if (t.kind == dsp::ProgramKind::circle)
    path_mm = 2.0 * 3.14159265358979 * t.radius_mm * t.arc_deg / 360.0 * t.repeats * (t.direction == "both" ? 2 : 1);
  else if (t.kind == dsp::ProgramKind::step)
    path_mm = 2.0 * std::abs(t.to_mm - t.from_mm) * t.runs;
  else if (t.kind == dsp::ProgramKind::positioning)
    path_mm = 2.0 * std::abs(t.targets_mm.back() - t.targets_mm.front()) * t.runs;
  else
    path_mm = 2.0 * (t.size_mm[0] + t.size_mm[1]) * std::max(1, t.repeats);
  return path_mm / (t.feed_mm_min / 60.0);
}

}  // namespace

Search search_measurable(const TestProgram& p, const SearchOptions& o) {
  Search out;
  const std::vector<TestProgram> all = variants(p);
  for (const TestProgram& t : all) out.tried.push_back({t, Outcome::not_reached, 0.0});
  const auto passed = [&] { return o.deadline && std::chrono::steady_clock::now() >= *o.deadline; };
  const int of = static_cast<int>(all.size());
  // One simulated identification per identification program (variants that share strips
  // and travel share it).
  std::map<std::string, dsp::SensorModelCovariance> identified;
  for (int n = 0; n < of; ++n) {
    Tried& tried = out.tried[static_cast<std::size_t>(n)];
    const TestProgram& t = tried.program;
    // Nothing simulated first: the envelope, and a rough duration (the path over the feed),
    // so that long variants are not.
    if (outside_envelope(t, o.envelope)) {
      tried.outcome = Outcome::outside_envelope;
      continue;
    }
    if (rough_duration_s(t) > o.max_duration_s) {
      tried.outcome = Outcome::too_long;
      continue;
    }
    std::optional<dsp::SensorModelCovariance> id = o.calibration;
    if (t.identified && !id) {
      const std::string key = identification_command(identification_plan(t));
      if (!identified.contains(key)) {
        if (passed()) break;
        if (o.progress) o.progress(0, of, t);
        identified.emplace(key, typical_identification(t));
      }
      id = identified.at(key);
    }
    if (passed()) break;
    if (o.progress) o.progress(n + 1, of, t);
    // Screened (Screen): a variant far above the limit is told by its first draws; a
    // nearer one is predicted with all of them.
    Prediction r = predict(t, 1, o.draws, id, Screen{});
    tried.outcome = r.measurable ? Outcome::measurable : Outcome::not_measurable;
    tried.limited_u = r.limited_u;
    if (r.measurable) {
      out.found = std::move(r);
      out.tried.resize(static_cast<std::size_t>(n) + 1);  // the rest were not needed
      return out;
    }
  }
  for (const Tried& t : out.tried) out.deadline_passed = out.deadline_passed || t.outcome == Outcome::not_reached;
  return out;
}

std::optional<Prediction> nearest_measurable(const TestProgram& p, double max_duration_s, int draws,
                                             const dsp::WorkEnvelope& envelope) {
  SearchOptions o;
  o.max_duration_s = max_duration_s, o.draws = draws, o.envelope = envelope;
  return search_measurable(p, o).found;
}

}  // namespace eical::tools::plan

namespace eical::tools::plan {

void suggest_measurable_test(const dsp::Run& run, dsp::Analysis& a) {
  const dsp::ResolutionLimit* lim = dsp::resolution_limit(run.meta.program.kind);
  if (!lim) return;
  // Whatever the pipeline compensated with: advice to identify the sensors only when they
  // were not (a calibration that disagrees is to be redone or checked, not made).
  if (a.measurement.supports.psd_disagrees)
    a.verdict_reasons.push_back(
        "the PSD readings disagree with " + sensor_model_text(a) +
        (a.sensor_model == "datasheet"
             ? ": identify the sensors (eical gen-nc identify, eical identify)"
             : ": identify the sensors again (eical gen-nc identify, eical identify) or check the calibration's run"));
  const auto it = a.uncertainty_k2.find(lim->limited);
  if (it == a.uncertainty_k2.end() || it->second.size() != 1 || !(it->second[0] > lim->limit)) {
    a.verdict_reasons.push_back(
        "the test resolves what it is meant to: the machine's figure is within the test's uncertainty");
    return;
  }
  TestProgram p;
  try {
    p = program_of(run.meta);
    p.identified = a.sensor_model != "datasheet";
    (void)scenario_of(p, 1);  // a kind plan knows
  } catch (const std::exception&) {
    return;
  }
  char b[256];
  if (const auto best = nearest_measurable(p, 30.0, 60, run.meta.envelope.value_or(dsp::WorkEnvelope{}))) {
    std::snprintf(b, sizeof b, "a test that would be measurable (eical plan): %s, predicted U(%s) = %.2f µm",
                  describe(best->program).c_str(), lim->limited_name, best->limited_u);
    a.verdict_reasons.push_back(b);
  } else {
    a.verdict_reasons.push_back("no nearby variant of this test is measurable (eical plan lists what was tried)");
  }
}

}  // namespace eical::tools::plan
