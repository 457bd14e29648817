// eical gen-nc {circle,positioning,step,rectangle,identify}: ISO G-code with the M101/
// M102/M103 measurement triggers, plus the [program] metadata a recorded run carries.
// On a real control the M-codes are user M-functions (LinuxCNC: executables M101..M103 in
// the PROGRAM_PREFIX directory, which call `eical trigger`; Siemens/Heidenhain: a PLC
// output wired to the trigger input, or a CAN frame) — see docs/service.md.
#include "dsp/core/error.hpp"
#include "sim/gcode/dialect.hpp"
#include "sim/gcode/generate.hpp"
#include "sim/nc/trajectory.hpp"
#include "tools/commands.hpp"
#include "tools/envelope_options.hpp"
#include "tools/io/psd_option.hpp"
#include "tools/program_defaults.hpp"

#include <cctype>
#include <cstdio>
#include <fstream>
#include <memory>
#include <optional>
#include <stdexcept>

namespace eical::tools {
namespace {

struct GenOptions {
  dsp::Program program;
  std::vector<double> center{0.0, 0.0};
  std::vector<double> corner{0.0, 0.0};
  std::vector<double> size{20.0, 10.0};
  double overrun_mm = 2.0;
  std::optional<double> arc_start_deg;
  std::string out;
  std::string meta_out;
  std::string dialect = "linuxcnc";
  int program_number = 1000;
  std::string program_name;
  EnvelopeOptions envelope;
};

std::string toml_list(const std::vector<double>& v) {
  std::string s = "[";
  for (std::size_t i = 0; i < v.size(); ++i) s += (i ? ", " : "") + std::to_string(v[i]);
  return s + "]";
}

// The [program] table of run.toml (docs/run-format.md) for this program.
std::string program_toml(const dsp::Program& p, const std::string& gcode) {
  std::string t =
      "[program]\nkind = \"" + std::string(dsp::program_kind_name(p.kind)) + "\"\nplane = \"" + p.plane + "\"\n";
  t += "feed_mm_min = " + std::to_string(p.feed_mm_min) + "\n";
  if (p.kind == dsp::ProgramKind::circle) {
    t += "center_mm = " + toml_list({p.center_mm[0], p.center_mm[1]}) + "\nradius_mm = " + std::to_string(p.radius_mm) +
         "\ndirection = \"" + p.direction + "\"\nrepeats = " + std::to_string(p.repeats) +
         "\narc_deg = " + std::to_string(p.arc_deg) + "\n";
    if (p.arc_deg < 360.0) t += "arc_start_deg = " + std::to_string(sim::gcode::partial_arc_start_deg(p)) + "\n";
  } else if (p.kind == dsp::ProgramKind::rectangle) {
    t += "corner_mm = " + toml_list({p.corner_mm[0], p.corner_mm[1]}) +
         "\nsize_mm = " + toml_list({p.size_mm[0], p.size_mm[1]}) + "\ndwell_s = " + std::to_string(p.dwell_s) +
         "\nrepeats = " + std::to_string(p.repeats) + "\n";
  } else {
    t += "axis = \"" + p.axis + "\"\ntargets_mm = " + toml_list(p.targets_mm) + "\nruns = " + std::to_string(p.runs) +
         "\ndwell_s = " + std::to_string(p.dwell_s) + "\n";
  }
  return t + "gcode = \"\"\"\n" + gcode + "\"\"\"\n";
}

void write_text(const std::string& path, const std::string& text) {
  if (path.empty() || path == "-") {
    std::fputs(text.c_str(), stdout);
    return;
  }
  std::ofstream os(path, std::ios::trunc);
  if (!os) throw std::runtime_error(path + ": cannot write");
  os << text;
  if (!os.flush()) throw std::runtime_error(path + ": write failed");
}

void add_output(CLI::App* cmd, std::string& out, std::string& meta_out, std::string& dialect, int& number,
                std::string& name) {
  cmd->add_option("-o,--out", out, "G-code file (default: standard output)");
  cmd->add_option("--meta", meta_out,
                  "also write the run's [program] table (TOML) here; its gcode is the program as eical simulates it");
  cmd->add_option("--dialect", dialect, "the control that runs it: linuxcnc, fanuc, sinumerik or heidenhain-iso")
      ->default_val("linuxcnc")
      ->check(CLI::IsMember({"linuxcnc", "fanuc", "sinumerik", "heidenhain-iso"}));
  cmd->add_option("--program-number", number, "FANUC program number O<n>")
      ->default_val(1000)
      ->check(CLI::Range(1, 9999));
  cmd->add_option("--program-name", name, "SINUMERIK / HEIDENHAIN program name (default EICAL_<KIND>)");
}
void add_output(CLI::App* cmd, GenOptions& o) {
  add_output(cmd, o.out, o.meta_out, o.dialect, o.program_number, o.program_name);
}

// The canonical program written for the control, and its [program] table with the
// LinuxCNC form (what eical's reader and simulator take).
// A program beyond the machine's work envelope is refused before anything is written: the
// program as eical's interpolator runs it (its arcs' extremes, its feeds).
void write_program(const std::string& canonical, dsp::Program p, const std::string& title, const std::string& out,
                   const std::string& meta_out, const std::string& dialect, int number, std::string name,
                   const EnvelopeOptions& envelope) {
  for (char& c : name)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_')
      throw std::runtime_error("--program-name: letters, digits and _ only");
  const sim::gcode::ProgramIdentity id{
      number, name.empty() ? "EICAL_" + std::string(dsp::program_kind_name(p.kind)) : name, title};
  p.gcode = sim::gcode::write_dialect(canonical, sim::gcode::Dialect::linuxcnc, id);
  const std::string what = "gen-nc " + std::string(dsp::program_kind_name(p.kind));
  require_within(sim::nc::interpolate_gcode(p.gcode, what, sim::nc::MachineLimits{}), envelope_of(envelope), what);
  write_text(out, sim::gcode::write_dialect(canonical, sim::gcode::dialect_from_name(dialect), id));
  if (!meta_out.empty()) write_text(meta_out, program_toml(p, p.gcode));
}

std::string title_of(const dsp::Program& p) {
  char b[160];
  if (p.kind == dsp::ProgramKind::circle)
    std::snprintf(b, sizeof b, "eical circle R%g F%g %s, %d revolutions, plane %s", p.radius_mm, p.feed_mm_min,
                  p.direction.c_str(), p.repeats, p.plane.c_str());
  else if (p.kind == dsp::ProgramKind::rectangle)
    std::snprintf(b, sizeof b, "eical rectangle %gx%g mm F%g, plane %s", p.size_mm[0], p.size_mm[1], p.feed_mm_min,
                  p.plane.c_str());
  else
    std::snprintf(b, sizeof b, "eical %s %s, %zu targets, %d runs, F%g", dsp::program_kind_name(p.kind), p.axis.c_str(),
                  p.targets_mm.size(), p.runs, p.feed_mm_min);
  return b;
}

void emit(GenOptions& o) {
  dsp::Program& p = o.program;
  p.center_mm[0] = o.center.at(0), p.center_mm[1] = o.center.at(1);
  p.corner_mm[0] = o.corner.at(0), p.corner_mm[1] = o.corner.at(1);
  p.size_mm[0] = o.size.at(0), p.size_mm[1] = o.size.at(1);
  const std::string g = p.kind == dsp::ProgramKind::positioning ? sim::gcode::positioning_program(p, o.overrun_mm)
                                                                : sim::gcode::program_gcode(p);
  write_program(g, p, title_of(p), o.out, o.meta_out, o.dialect, o.program_number, o.program_name, o.envelope);
}

// One option set per program kind: CLI11 writes defaults into the bound variables when
// the options are declared, so kinds must not share them.
void add_circle(CLI::App* gen) {
  auto o = std::make_shared<GenOptions>();
  dsp::Program& p = o->program;
  auto* c = gen->add_subcommand("circle", "ISO 230-4 circular test");
  c->add_option("--radius", p.radius_mm, "radius in mm")
      ->default_val(program_defaults::kCircleRadiusMm)
      ->check(CLI::PositiveNumber);
  c->add_option("--feed", p.feed_mm_min, "feed in mm/min")
      ->default_val(program_defaults::kCircleFeedMmMin)
      ->check(CLI::PositiveNumber);
  c->add_option("--repeats", p.repeats, "full revolutions")
      ->default_val(program_defaults::kCircleRevolutions)
      ->check(CLI::Range(1, 1000));
  c->add_option("--direction", p.direction, "ccw, cw or both (ccw, then cw back)")
      ->default_val("ccw")
      ->check(CLI::IsMember({"ccw", "cw", "both"}));
  c->add_option("--plane", p.plane, "xy, zx or yz")->default_val("xy")->check(CLI::IsMember({"xy", "zx", "yz"}));
  c->add_option("--center", o->center, "centre in the plane, mm")->expected(2)->delimiter(',');
  c->add_option("--arc-deg", p.arc_deg, "evaluated arc in deg: 360 = full circle, up to 340 for a partial arc")
      ->default_val(360.0)
      ->check(CLI::Range(1.0, 360.0));
  c->add_option("--arc-start-deg", o->arc_start_deg, "partial arc: where it begins, deg (default 90 - arc/2)");
  add_output(c, *o);
  add_envelope_options(*c, o->envelope);
  c->callback([o] {
    o->program.kind = dsp::ProgramKind::circle;
    if (o->arc_start_deg) o->program.arc_start_deg = *o->arc_start_deg;
    emit(*o);
  });
}

void add_positioning(CLI::App* gen) {
  auto o = std::make_shared<GenOptions>();
  dsp::Program& p = o->program;
  auto* c = gen->add_subcommand("positioning", "ISO 230-2 bidirectional positioning cycle");
  c->add_option("--axis", p.axis, "x, y or z")->default_val("x")->check(CLI::IsMember({"x", "y", "z"}));
  c->add_option("--targets", p.targets_mm, "targets in mm, ascending (comma separated)")->required()->delimiter(',');
  c->add_option("--runs", p.runs, "bidirectional runs")
      ->default_val(program_defaults::kPositioningRuns)
      ->check(CLI::Range(1, 1000));
  c->add_option("--feed", p.feed_mm_min, "feed in mm/min")
      ->default_val(program_defaults::kPositioningFeedMmMin)
      ->check(CLI::PositiveNumber);
  c->add_option("--dwell", p.dwell_s, "dwell at each target in s")->default_val(0.5)->check(CLI::Range(0.0, 3600.0));
  c->add_option("--overrun", o->overrun_mm, "overrun beyond the end targets in mm")
      ->default_val(2.0)
      ->check(CLI::NonNegativeNumber);
  add_output(c, *o);
  add_envelope_options(*c, o->envelope);
  c->callback([o] {
    o->program.kind = dsp::ProgramKind::positioning;
    emit(*o);
  });
}

void add_step(CLI::App* gen) {
  auto o = std::make_shared<GenOptions>();
  dsp::Program& p = o->program;
  auto* c = gen->add_subcommand("step", "step response: back and forth between two targets");
  c->add_option("--axis", p.axis, "x, y or z")->default_val("x")->check(CLI::IsMember({"x", "y", "z"}));
  c->add_option("--targets", p.targets_mm, "a,b in mm")->required()->expected(2)->delimiter(',');
  c->add_option("--runs", p.runs, "there-and-back pairs")
      ->default_val(program_defaults::kStepPairs)
      ->check(CLI::Range(1, 1000));
  c->add_option("--feed", p.feed_mm_min, "feed in mm/min")
      ->default_val(program_defaults::kStepFeedMmMin)
      ->check(CLI::PositiveNumber);
  c->add_option("--dwell", p.dwell_s, "dwell at each end in s")->default_val(0.5)->check(CLI::Range(0.0, 3600.0));
  add_output(c, *o);
  add_envelope_options(*c, o->envelope);
  c->callback([o] {
    o->program.kind = dsp::ProgramKind::step;
    emit(*o);
  });
}

void add_rectangle(CLI::App* gen) {
  auto o = std::make_shared<GenOptions>();
  dsp::Program& p = o->program;
  auto* c = gen->add_subcommand("rectangle", "rectangle with exact stop at the corners");
  c->add_option("--corner", o->corner, "start corner in the plane, mm")->expected(2)->delimiter(',');
  c->add_option("--size", o->size, "side lengths, mm")->expected(2)->delimiter(',');
  c->add_option("--feed", p.feed_mm_min, "feed in mm/min")
      ->default_val(program_defaults::kRectangleFeedMmMin)
      ->check(CLI::PositiveNumber);
  c->add_option("--dwell", p.dwell_s, "dwell at each corner in s")->default_val(0.2)->check(CLI::Range(0.0, 3600.0));
  c->add_option("--repeats", p.repeats, "laps")
      ->default_val(program_defaults::kRectangleLaps)
      ->check(CLI::Range(1, 1000));
  c->add_option("--plane", p.plane, "xy, zx or yz")->default_val("xy")->check(CLI::IsMember({"xy", "zx", "yz"}));
  add_output(c, *o);
  add_envelope_options(*c, o->envelope);
  c->callback([o] {
    o->program.kind = dsp::ProgramKind::rectangle;
    emit(*o);
  });
}

void add_identify(CLI::App* gen) {
  struct Id {
    std::vector<std::string> psd, axes, travel;
    sim::gcode::IdentifyPlan plan;
    std::string out, meta_out, dialect = "linuxcnc", name;
    int number = 1000;
    EnvelopeOptions envelope;
  };
  auto o = std::make_shared<Id>();
  auto* c =
      gen->add_subcommand("identify", "on-site sensor identification: swings across the PSD strips (and further axes)");
  c->add_option("--psd", o->psd, "a strip as MEASURES:CX,CY, e.g. x:0,-10 (repeat for each strip)");
  c->add_option("--axis", o->axes, "a further axis to swing without a strip, e.g. z (repeatable)")
      ->check(CLI::IsMember({"x", "y", "z"}));
  c->add_option("--swing", o->plan.swing_mm, "swing, peak to peak, mm")->default_val(50.0);
  c->add_option("--travel", o->travel,
                "AXIS:LO,HI: the swings along x or y stay inside LO…HI mm, e.g. the test's travel (repeatable)");
  c->add_option("--feeds", o->plan.feeds_mm_min, "feeds in mm/min (comma separated)")
      ->delimiter(',')
      ->default_str("2000,4000,6500");
  add_output(c, o->out, o->meta_out, o->dialect, o->number, o->name);
  add_envelope_options(*c, o->envelope);
  c->callback([o] {
    for (const auto& t : o->psd) o->plan.psd.push_back(parse_psd(t));
    for (const auto& t : o->travel) {
      const TravelOption tr = parse_travel(t);
      if (tr.axis > 1) throw dsp::InputError("--travel '" + t + "': identify swings x and y across strips, z freely");
      o->plan.travel_mm[tr.axis] = sim::gcode::AxisTravel{tr.lo_mm, tr.hi_mm};
    }
    o->plan.axes = o->axes;
    if (o->plan.feeds_mm_min.empty()) o->plan.feeds_mm_min = {2000.0, 4000.0, 6500.0};
    const std::string g = sim::gcode::identify_program(o->plan);
    dsp::Program p;
    p.kind = dsp::ProgramKind::identify;
    write_program(g, p, "eical identify: swings across the PSD strips", o->out, o->meta_out, o->dialect, o->number,
                  o->name, o->envelope);
  });
}

}  // namespace

void register_gen_nc(CLI::App& app) {
  auto* gen = app.add_subcommand("gen-nc", "Write a calibration NC program (ISO G-code with M101/M102/M103)");
  gen->require_subcommand(1);
  add_circle(gen);
  add_positioning(gen);
  add_step(gen);
  add_rectangle(gen);
  add_identify(gen);
}

}  // namespace eical::tools
