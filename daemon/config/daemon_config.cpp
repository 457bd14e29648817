#include "daemon/config/daemon_config.hpp"

#include "drivers/config/meta_sections.hpp"
#include "drivers/config/strict_toml.hpp"
#include "drivers/setpoint/program_catalog.hpp"
#include "dsp/core/error.hpp"
#include "dsp/core/frame.hpp"

#include <cmath>

namespace eical::daemon {
namespace {

using drivers::StrictTable;

// The [program] table of a file written by `eical gen-nc ... --meta`; errors inside it
// name that file and line, and the key that named the file.
dsp::Program read_program_file(StrictTable& t, const std::filesystem::path& path) {
  try {
    return drivers::read_program_file(path);
  } catch (const dsp::InputError& e) {
    t.fail("program_file", e.what());
  }
}

void read_linuxcnc(StrictTable t, LinuxcncConfig& l) {
  l.fifo = t.string("fifo", l.fifo.string());
  if (l.fifo.empty()) t.fail("fifo", "must not be empty");
  l.program_file = t.string("program_file", l.program_file.string());
  if (l.program_file.empty())
    t.fail("program_file", "required: the [program] table (eical gen-nc --meta) of what LinuxCNC runs");
  l.program_loaded = read_program_file(t, l.program_file);
  l.scenario_file = t.string("scenario_file", l.scenario_file.string());
  l.servo_rate_hz = t.number("servo_rate_hz", l.servo_rate_hz);
  if (l.servo_rate_hz < 100.0 || l.servo_rate_hz > 20000.0) t.fail("servo_rate_hz", "must be within 100..20000");
  l.block_ms = t.number("block_ms", l.block_ms);
  if (l.block_ms < 20.0 || l.block_ms > 5000.0) t.fail("block_ms", "must be within 20..5000");
  l.history_ms = t.number("history_ms", l.history_ms);
  if (l.history_ms < 10.0 || l.history_ms > 10000.0) t.fail("history_ms", "must be within 10..10000");
  l.drive = t.choice("drive", {"command", "feedback"}, l.drive);
  l.connect_timeout_s = t.number("connect_timeout_s", l.connect_timeout_s);
  if (l.connect_timeout_s < 0.1 || l.connect_timeout_s > 3600.0)
    t.fail("connect_timeout_s", "must be within 0.1..3600");
  l.stall_timeout_s = t.number("stall_timeout_s", l.stall_timeout_s);
  if (l.stall_timeout_s < 0.1 || l.stall_timeout_s > 3600.0) t.fail("stall_timeout_s", "must be within 0.1..3600");
  l.hold_ms = t.number("hold_ms", l.hold_ms);
  if (l.hold_ms < 0.0 || l.hold_ms > 10000.0) t.fail("hold_ms", "must be within 0..10000");
  const auto seed = t.integer("seed", static_cast<std::int64_t>(l.seed));
  if (seed < 0) t.fail("seed", "must not be negative");
  l.seed = static_cast<std::uint64_t>(seed);
  t.finish();
}

void read_daq_stream(StrictTable t, DaqStreamConfig& d) {
  d.path = t.string("path", d.path.string());
  if (d.path.empty()) t.fail("path", "must not be empty");
  d.connect_timeout_s = t.number("connect_timeout_s", d.connect_timeout_s);
  if (d.connect_timeout_s < 0.1 || d.connect_timeout_s > 3600.0)
    t.fail("connect_timeout_s", "must be within 0.1..3600");
  d.stall_timeout_s = t.number("stall_timeout_s", d.stall_timeout_s);
  if (d.stall_timeout_s < 0.05 || d.stall_timeout_s > 3600.0) t.fail("stall_timeout_s", "must be within 0.05..3600");
  t.finish();
}

void read_source(StrictTable t, SourceConfig& s) {
  s.kind = t.choice("kind", {"sim", "replay", "usb_daq", "daq_stream", "linuxcnc"}, s.kind);
  s.pacing = t.choice("pacing", {"realtime", "free_running"}, s.pacing);
  s.replay_run = t.string("replay_run", s.replay_run.string());
  if (s.kind == "replay" && s.replay_run.empty()) t.fail("replay_run", "required when kind = \"replay\"");
  s.usb_id = t.string("usb_id", s.usb_id);
  if (auto sim = t.optional_table("sim")) {
    s.sim_program =
        *dsp::parse_program_kind(sim->choice("program", {"circle", "step"}, dsp::program_kind_name(s.sim_program)));
    s.sim_radius_mm = sim->number("radius_mm", s.sim_radius_mm);
    if (!(s.sim_radius_mm > 0.0)) sim->fail("radius_mm", "must be positive");
    s.sim_feed_mm_min = sim->number("feed_mm_min", s.sim_feed_mm_min);
    if (!(s.sim_feed_mm_min > 0.0)) sim->fail("feed_mm_min", "must be positive");
    s.sim_repeats = sim->int32("repeats", s.sim_repeats);
    // The program is generated (and checked against [envelope]) at load: bounded.
    if (s.sim_repeats < 1 || s.sim_repeats > 1000) sim->fail("repeats", "must be within 1..1000");
    const auto seed = sim->integer("seed", static_cast<std::int64_t>(s.sim_seed));
    if (seed < 0) sim->fail("seed", "must not be negative");
    s.sim_seed = static_cast<std::uint64_t>(seed);
    s.sim_idle_s = sim->number("idle_s", s.sim_idle_s);
    if (s.sim_idle_s < 0.0) sim->fail("idle_s", "must not be negative");
    s.sim_repeat_program = sim->boolean("repeat_program", s.sim_repeat_program);
    s.sim_program_file = sim->string("program_file", s.sim_program_file.string());
    if (!s.sim_program_file.empty()) s.sim_program_loaded = read_program_file(*sim, s.sim_program_file);
    sim->finish();
  }
  if (auto l = t.optional_table("linuxcnc")) read_linuxcnc(*l, s.linuxcnc);
  if (auto d = t.optional_table("daq_stream")) read_daq_stream(*d, s.daq_stream);
  if (s.kind == "linuxcnc" && !s.linuxcnc.program_loaded)
    t.fail("linuxcnc", "[source.linuxcnc] with program_file is required when kind = \"linuxcnc\"");
  s.retry_s = t.number("retry_s", s.retry_s);
  if (s.retry_s < 0.1 || s.retry_s > 3600.0) t.fail("retry_s", "must be within 0.1..3600");
  if (auto f = t.optional_table("fault")) {
    auto& p = s.fault;
    p.fail_at_s = f->number("fail_at_s", p.fail_at_s);
    p.gap_at_s = f->number("gap_at_s", p.gap_at_s);
    const auto gap = f->integer("gap_frames", p.gap_frames);
    if (gap < 0) f->fail("gap_frames", "must not be negative");
    p.gap_frames = gap;
    p.saturate_at_s = f->number("saturate_at_s", p.saturate_at_s);
    p.saturate_s = f->number("saturate_s", p.saturate_s);
    p.saturate_channel = f->int32("saturate_channel", p.saturate_channel);
    if (p.saturate_channel < 0 || p.saturate_channel > 5) f->fail("saturate_channel", "must be within 0..5");
    p.nan_at_s = f->number("nan_at_s", p.nan_at_s);
    p.nan_s = f->number("nan_s", p.nan_s);
    p.hang_dsp_at_s = f->number("hang_dsp_at_s", p.hang_dsp_at_s);
    f->finish();
  }
  t.finish();
}

void read_setpoint(StrictTable t, SetPointConfig& c, const SourceConfig& source) {
  c.source = t.choice("source", {"none", "servo_stream", "program"}, c.source);
  if (c.source != "none" && !source.is_daq())
    t.fail("source", "a set-point source goes next to a DAQ ([source] kind = \"usb_daq\" or \"daq_stream\"); the " +
                         source.kind + " source brings its own set-point");
  if (auto s = t.optional_table("servo_stream")) {
    c.servo_fifo = s->string("fifo", c.servo_fifo.string());
    if (c.servo_fifo.empty()) s->fail("fifo", "must not be empty");
    c.servo_rate_hz = s->number("servo_rate_hz", c.servo_rate_hz);
    if (c.servo_rate_hz < 100.0 || c.servo_rate_hz > 20000.0) s->fail("servo_rate_hz", "must be within 100..20000");
    c.hold_ms = s->number("hold_ms", c.hold_ms);
    if (c.hold_ms < 20.0 || c.hold_ms > 10000.0)
      s->fail("hold_ms", "must be within 20..10000 (the servo lines arrive ~10 ms late)");
    s->finish();
  }
  if (auto s = t.optional_table("program")) {
    c.program_dir = s->string("directory", c.program_dir.string());
    if (c.program_dir.empty()) s->fail("directory", "must not be empty");
    c.default_program = static_cast<int>(s->integer("default_program", c.default_program));
    if (c.default_program < -1) s->fail("default_program", "must be a program number (0 or more) or -1 for none");
    c.mcode_stops = s->boolean("mcode_stops", c.mcode_stops);
    c.max_lag_s = s->number("max_lag_s", c.max_lag_s);
    if (c.max_lag_s < 0.005 || c.max_lag_s > 5.0) s->fail("max_lag_s", "must be within 0.005..5");
    c.a_max_mm_s2 = s->number("a_max_mm_s2", c.a_max_mm_s2);
    if (c.a_max_mm_s2 <= 0.0) s->fail("a_max_mm_s2", "must be positive");
    c.j_max_mm_s3 = s->number("j_max_mm_s3", c.j_max_mm_s3);
    if (c.j_max_mm_s3 <= 0.0) s->fail("j_max_mm_s3", "must be positive");
    c.rapid_mm_min = s->number("rapid_mm_min", c.rapid_mm_min);
    if (c.rapid_mm_min <= 0.0) s->fail("rapid_mm_min", "must be positive");
    s->finish();
  }
  t.finish();
}

void read_triggers(StrictTable t, TriggerConfig& c) {
  if (t.has("inputs")) c.inputs = t.strings("inputs");
  for (const auto& in : c.inputs)
    if (in != "frame" && in != "dds" && in != "gpio" && in != "can")
      t.fail("inputs", "'" + in + "' is not one of: frame, dds, gpio, can");
  c.gpio_chip = t.string("gpio_chip", c.gpio_chip);
  if (t.has("gpio_lines")) {
    const auto lines = t.numbers("gpio_lines", 3);
    for (std::size_t i = 0; i < 3; ++i) {
      // Checked before the conversion: a double beyond int's range does not convert.
      if (!(lines[i] >= 0.0 && lines[i] <= 65535.0) || lines[i] != std::floor(lines[i]))
        t.fail("gpio_lines", "line offsets must be integers within 0..65535");
      c.gpio_lines[i] = static_cast<int>(lines[i]);
    }
  }
  c.gpio_debounce_ms = t.number("gpio_debounce_ms", c.gpio_debounce_ms);
  if (c.gpio_debounce_ms < 0.0 || c.gpio_debounce_ms > 1000.0) t.fail("gpio_debounce_ms", "must be within 0..1000");
  c.can_interface = t.string("can_interface", c.can_interface);
  const auto id = t.integer("can_id", c.can_id);
  if (id < 0 || id > 0x7FF) t.fail("can_id", "must be a standard 11-bit CAN id (0..0x7FF)");
  c.can_id = static_cast<std::uint32_t>(id);
  t.finish();
}

void read_dds(StrictTable t, DdsConfig& d) {
  d.domain_id = t.int32("domain_id", d.domain_id);
  if (d.domain_id < 0 || d.domain_id > 232) t.fail("domain_id", "must be within 0..232");
  d.config_uri = t.string("config_uri", d.config_uri);
  d.live_rate_hz = t.number("live_rate_hz", d.live_rate_hz);
  if (d.live_rate_hz < 1.0 || d.live_rate_hz > 1000.0) t.fail("live_rate_hz", "must be within 1..1000");
  d.status_rate_hz = t.number("status_rate_hz", d.status_rate_hz);
  if (d.status_rate_hz <= 0.0 || d.status_rate_hz > 50.0) t.fail("status_rate_hz", "must be within (0, 50]");
  const auto points = t.integer("trace_max_points", static_cast<std::int64_t>(d.trace_max_points));
  if (points < 100 || points > 1000000) t.fail("trace_max_points", "must be within 100..1000000");
  d.trace_max_points = static_cast<std::size_t>(points);
  t.finish();
}

void read_recording(StrictTable t, RecordingConfig& r) {
  r.dir = t.string("dir", r.dir.string());
  if (r.dir.empty()) t.fail("dir", "must not be empty");
  r.gzip = t.boolean("gzip", r.gzip);
  t.finish();
}

void read_history(StrictTable t, HistoryConfig& h) {
  h.enabled = t.boolean("enabled", h.enabled);
  h.db = t.string("db", h.db);
  if (h.db.empty()) t.fail("db", "must not be empty (a SQLite file or a postgresql:// URI)");
  h.spool_dir = t.string("spool_dir", h.spool_dir.string());
  if (h.spool_dir.empty()) t.fail("spool_dir", "must not be empty");
  h.retry_s = t.number("retry_s", h.retry_s);
  if (h.retry_s < 0.1 || h.retry_s > 3600.0) t.fail("retry_s", "must be within 0.1..3600");
  t.finish();
}

void read_limits(StrictTable t, Limits& l) {
  const auto cap = t.integer("ring_capacity_frames", static_cast<std::int64_t>(l.ring_capacity_frames));
  if (cap < 1024 || (cap & (cap - 1)) != 0) t.fail("ring_capacity_frames", "must be a power of two >= 1024");
  l.ring_capacity_frames = static_cast<std::size_t>(cap);
  l.max_measurement_s = t.number("max_measurement_s", l.max_measurement_s);
  if (l.max_measurement_s <= 0.0 || l.max_measurement_s > 3600.0)
    t.fail("max_measurement_s", "must be within (0, 3600]");
  l.temp_min_c = t.number("temp_min_c", l.temp_min_c);
  l.temp_max_c = t.number("temp_max_c", l.temp_max_c);
  if (l.temp_max_c <= l.temp_min_c) t.fail("temp_max_c", "must be above temp_min_c");
  const auto lost = t.integer("max_lost_frames", static_cast<std::int64_t>(l.max_lost_frames));
  // A lost frame is bridged with the last value by the integration: the result is degraded
  // whatever the count (quality flag frames_lost). Tolerating some would need a lost-frame
  // model in the uncertainty; until then only 0 says what happens.
  if (lost != 0)
    t.fail("max_lost_frames", "only 0 is supported: every lost frame flags the result degraded (frames_lost)");
  l.max_lost_frames = static_cast<std::uint64_t>(lost);
  t.finish();
}

void read_realtime(StrictTable t, RealtimeConfig& r) {
  r.sched_fifo_priority = t.int32("sched_fifo_priority", r.sched_fifo_priority);
  if (r.sched_fifo_priority < 0 || r.sched_fifo_priority > 99) t.fail("sched_fifo_priority", "must be within 0..99");
  r.mlockall = t.boolean("mlockall", r.mlockall);
  t.finish();
}

// The program the simulated NC runs ([source.sim]) must stay within [envelope]: the
// service would otherwise simulate, record and evaluate a machine that cannot exist.
void require_within_envelope(const DaemonConfig& c, StrictTable& t) {
  if (c.source.kind != "sim") return;
  if (const auto x = drivers::sim_program_outside_envelope(sim_machine(c)))
    t.fail("envelope", "the simulated NC's program ([source.sim]): " + x->text + " (" + x->key + ")");
}

}  // namespace

DaemonConfig load_daemon_config(const std::filesystem::path& file) {
  const toml::table root = StrictTable::parse_file(file.string());
  StrictTable t(root, file.string(), "");
  DaemonConfig c;
  c.file = file.string();
  if (auto s = t.optional_table("source")) read_source(*s, c.source);
  if (auto s = t.optional_table("setpoint")) read_setpoint(*s, c.setpoint, c.source);
  if (auto s = t.optional_table("triggers")) read_triggers(*s, c.triggers);
  if (auto s = t.optional_table("dds")) read_dds(*s, c.dds);
  if (auto s = t.optional_table("recording")) read_recording(*s, c.recording);
  if (auto s = t.optional_table("history")) read_history(*s, c.history);
  if (auto s = t.optional_table("limits")) read_limits(*s, c.limits);
  if (auto s = t.optional_table("realtime")) read_realtime(*s, c.realtime);
  if (auto s = t.optional_table("acquisition")) c.acquisition = drivers::read_acquisition(*s);
  if (auto s = t.optional_table("site")) c.site = drivers::read_site(*s);
  if (auto s = t.optional_table("machine")) c.machine = drivers::read_machine(*s);
  if (auto s = t.optional_table("envelope")) c.envelope = drivers::read_envelope(*s);
  if (auto s = t.optional_table("sensors")) {
    if (auto table = s->optional_table("table")) c.sensors[0] = drivers::read_sensor(*table);
    if (auto head = s->optional_table("head")) c.sensors[1] = drivers::read_sensor(*head);
    s->finish();
  }
  if (auto s = t.optional_table("calibration")) {
    c.calibration_file = s->string("file", "");
    s->finish();
  }
  for (auto& p : t.tables("psd")) c.psd.push_back(drivers::read_psd(p));
  if (c.psd.size() > static_cast<std::size_t>(dsp::kMaxPsd))  // a frame carries that many
    t.fail("psd", std::to_string(c.psd.size()) + " strips, at most " + std::to_string(dsp::kMaxPsd));
  if (c.triggers.inputs.empty())
    t.fail("triggers", "no trigger input configured: the NC could not start a measurement");
  require_within_envelope(c, t);
  if (c.history.enabled && c.machine.name.empty())
    t.fail("history", "[machine] name is required: the history keys results by machine");
  t.finish();
  return c;
}

dsp::RunMeta hardware_meta(const DaemonConfig& c) {
  dsp::RunMeta meta;
  meta.acquisition = c.acquisition;
  meta.site = c.site;
  meta.machine = c.machine;
  meta.envelope = c.envelope;
  meta.sensors[0] = c.sensors[0];
  meta.sensors[1] = c.sensors[1];
  meta.psd = c.psd;
  meta.program.kind = dsp::ProgramKind::freeform;
  return meta;
}

drivers::SimMachine sim_machine(const DaemonConfig& c) {
  const SourceConfig& s = c.source;
  drivers::SimMachine m;
  m.program = s.sim_program_loaded;
  m.builtin = s.sim_program;
  m.radius_mm = s.sim_radius_mm, m.feed_mm_min = s.sim_feed_mm_min;
  m.repeats = s.sim_repeats;
  m.seed = s.sim_seed;
  m.meta = hardware_meta(c);
  return m;
}

}  // namespace eical::daemon
