#include "drivers/config/meta_sections.hpp"
#include "drivers/config/strict_eigen.hpp"

#include <Eigen/LU>

#include <algorithm>
#include <cmath>

namespace eical::drivers {
namespace {

bool valid_axis(const std::string& a) { return a == "x" || a == "y" || a == "z"; }

}  // namespace

dsp::Acquisition read_acquisition(StrictTable t, const dsp::Acquisition& defaults) {
  dsp::Acquisition a = defaults;
  a.fs_hz = t.number("fs_hz", a.fs_hz);
  if (a.fs_hz <= 0.0) t.fail("fs_hz", "must be positive");
  a.adc_bits = t.int32("adc_bits", a.adc_bits);
  if (a.adc_bits < 8 || a.adc_bits > 32) t.fail("adc_bits", "must be between 8 and 32");
  a.adc_lsb_volt = t.number("adc_lsb_volt", a.adc_lsb_volt);
  if (a.adc_lsb_volt <= 0.0) t.fail("adc_lsb_volt", "must be positive");
  a.adc_offset_counts = t.integer("adc_offset_counts", a.adc_offset_counts);
  a.daq_group_delay_samples = t.number("daq_group_delay_samples", a.daq_group_delay_samples);
  if (a.daq_group_delay_samples < 0.0) t.fail("daq_group_delay_samples", "must not be negative");
  a.daq_skew_head_samples = t.number("daq_skew_head_samples", a.daq_skew_head_samples);
  if (!(std::abs(a.daq_skew_head_samples) < 1000.0))
    t.fail("daq_skew_head_samples", "must be within (-1000, 1000) samples");
  t.finish();
  return a;
}

dsp::Site read_site(StrictTable t, const dsp::Site& defaults) {
  dsp::Site s = defaults;
  s.latitude_deg = t.number("latitude_deg", s.latitude_deg);
  if (s.latitude_deg < -90.0 || s.latitude_deg > 90.0) t.fail("latitude_deg", "must be within [-90, 90]");
  s.heading_deg = t.number("heading_deg", s.heading_deg);
  s.g_mps2 = t.number("g_mps2", s.g_mps2);
  if (s.g_mps2 < 9.7 || s.g_mps2 > 9.9) t.fail("g_mps2", "local gravity must be within [9.7, 9.9] m/s^2");
  t.finish();
  return s;
}

dsp::MachineLayout read_machine(StrictTable t, const dsp::MachineLayout& defaults) {
  dsp::MachineLayout m = defaults;
  m.name = t.string("name", m.name);
  if (t.has("table_axes")) m.table_axes = t.strings("table_axes");
  if (t.has("head_axes")) m.head_axes = t.strings("head_axes");
  for (const auto* list : {&m.table_axes, &m.head_axes})
    for (const auto& a : *list)
      if (!valid_axis(a))
        t.fail(list == &m.table_axes ? "table_axes" : "head_axes", "axis '" + a + "' is not x, y or z");
  for (const auto& a : m.table_axes)
    if (std::find(m.head_axes.begin(), m.head_axes.end(), a) != m.head_axes.end())
      t.fail("head_axes", "axis '" + a + "' is moved by both table and head");
  t.finish();
  return m;
}

dsp::SensorSpec read_sensor(StrictTable t, const dsp::SensorSpec& defaults) {
  dsp::SensorSpec s = defaults;
  s.model = t.string("model", s.model);
  if (t.has("to_machine")) {
    const auto rows = t.matrix("to_machine", 3, 3);
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) s.to_machine(r, c) = rows[static_cast<std::size_t>(r)][static_cast<std::size_t>(c)];
    // A mounting matrix is a rotation (plus small misalignment): reject typos such as a zero row.
    if (std::abs(s.to_machine.determinant()) < 0.5) t.fail("to_machine", "matrix is singular or far from a rotation");
  }
  s.k1_v_per_g = vec3_or(t, "k1_v_per_g", s.k1_v_per_g);
  for (int i = 0; i < 3; ++i)
    if (!(s.k1_v_per_g[i] > 0.0)) t.fail("k1_v_per_g", "scale factors must be positive");
  s.k2_g_per_g2 = vec3_or(t, "k2_g_per_g2", s.k2_g_per_g2);
  s.k3_g_per_g3 = vec3_or(t, "k3_g_per_g3", s.k3_g_per_g3);
  s.bias_g = vec3_or(t, "bias_g", s.bias_g);
  s.tc_k1_ppm_per_c = t.number("tc_k1_ppm_per_c", s.tc_k1_ppm_per_c);
  s.tc_bias_ug_per_c = t.number("tc_bias_ug_per_c", s.tc_bias_ug_per_c);
  s.f0_hz = t.number("f0_hz", s.f0_hz);
  if (s.f0_hz <= 0.0) t.fail("f0_hz", "must be positive");
  s.zeta = t.number("zeta", s.zeta);
  if (s.zeta <= 0.0 || s.zeta > 5.0) t.fail("zeta", "must be within (0, 5]");
  s.zeta_per_g = t.number("zeta_per_g", s.zeta_per_g);
  if (!(std::abs(s.zeta_per_g) <= 100.0)) t.fail("zeta_per_g", "must be within [-100, 100] per g");
  s.noise_ug_per_rthz = t.number("noise_ug_per_rthz", s.noise_ug_per_rthz);
  if (s.noise_ug_per_rthz < 0.0) t.fail("noise_ug_per_rthz", "must not be negative");
  s.bias_walk_ug_per_rts = t.number("bias_walk_ug_per_rts", s.bias_walk_ug_per_rts);
  if (!(s.bias_walk_ug_per_rts >= 0.0 && s.bias_walk_ug_per_rts < 1e6))
    t.fail("bias_walk_ug_per_rts", "must be within [0, 1e6) µg/√s");
  s.temp_ref_c = t.number("temp_ref_c", s.temp_ref_c);
  t.finish();
  return s;
}

dsp::PsdSpec read_psd(StrictTable t) {
  dsp::PsdSpec p;
  p.measures = t.choice("measures", {"x", "y", "z"}, p.measures);
  const auto c = t.numbers("center_mm", 2);
  p.center_mm[0] = c[0];
  p.center_mm[1] = c[1];
  p.length_mm = t.number("length_mm", p.length_mm);
  if (p.length_mm <= 0.0) t.fail("length_mm", "must be positive");
  p.width_mm = t.number("width_mm", p.width_mm);
  p.lockin_tau_s = t.number("lockin_tau_s", p.lockin_tau_s);
  t.finish();
  return p;
}

dsp::Program read_program(StrictTable t) {
  dsp::Program p;
  std::vector<std::string> kinds;
  for (const auto& [kind, name] : dsp::kProgramKindNames) kinds.emplace_back(name);
  (void)t.string("kind");  // required: a run says which program it carries
  p.kind = dsp::parse_program_kind(t.choice("kind", kinds, "circle")).value_or(p.kind);
  p.plane = t.choice("plane", {"xy", "zx", "yz"}, p.plane);
  if (t.has("center_mm")) {
    const auto c = t.numbers("center_mm", 2);
    p.center_mm[0] = c[0], p.center_mm[1] = c[1];
  }
  p.radius_mm = t.number("radius_mm", p.radius_mm);
  if (p.radius_mm <= 0.0) t.fail("radius_mm", "must be positive");
  p.feed_mm_min = t.number("feed_mm_min", p.feed_mm_min);
  if (p.feed_mm_min <= 0.0) t.fail("feed_mm_min", "must be positive");
  p.direction = t.choice("direction", {"cw", "ccw", "both"}, p.direction);
  p.arc_deg = t.number("arc_deg", p.arc_deg);
  if (!(p.arc_deg > 0.0 && p.arc_deg <= 360.0)) t.fail("arc_deg", "must be in (0, 360]");
  if (t.has("arc_start_deg")) p.arc_start_deg = t.number("arc_start_deg");
  p.repeats = t.int32("repeats", p.repeats);
  if (p.repeats < 1) t.fail("repeats", "must be at least 1");
  p.axis = t.choice("axis", {"x", "y", "z"}, p.axis);
  if (t.has("targets_mm")) p.targets_mm = t.numbers("targets_mm");
  p.runs = t.int32("runs", p.runs);
  if (p.runs < 1) t.fail("runs", "must be at least 1");
  p.dwell_s = t.number("dwell_s", p.dwell_s);
  if (p.dwell_s < 0.0) t.fail("dwell_s", "must not be negative");
  if (t.has("corner_mm")) {
    const auto c = t.numbers("corner_mm", 2);
    p.corner_mm[0] = c[0], p.corner_mm[1] = c[1];
  }
  if (t.has("size_mm")) {
    const auto c = t.numbers("size_mm", 2);
    p.size_mm[0] = c[0], p.size_mm[1] = c[1];
  }
  p.gcode = t.string("gcode", "");
  t.finish();
  return p;
}

dsp::SetPointOrigin read_setpoint_origin(StrictTable t) {
  dsp::SetPointOrigin s;
  s.source = t.choice("source", {"servo_stream", "program"}, "servo_stream");
  s.servo_cycle_at_first_sample = t.number("servo_cycle_at_first_sample", s.servo_cycle_at_first_sample);
  s.servo_rate_hz = t.number("servo_rate_hz", s.servo_rate_hz);
  s.program_number = static_cast<int>(t.integer("program_number", s.program_number));
  s.marks_offset_s = t.number("marks_offset_s", s.marks_offset_s);
  s.offset_s = t.number("offset_s", s.offset_s);
  s.blocks = static_cast<int>(t.integer("blocks", s.blocks));
  s.block_offset_spread_s = t.number("block_offset_spread_s", s.block_offset_spread_s);
  s.lag_s = t.number("lag_s", s.lag_s);
  s.correlation = t.number("correlation", s.correlation);
  s.residual_ratio = t.number("residual_ratio", s.residual_ratio);
  t.finish();
  return s;
}

dsp::WorkEnvelope read_envelope(StrictTable t, const dsp::WorkEnvelope& defaults) {
  // Sanity bounds, not a machine: the largest gantry mills travel tens of metres.
  constexpr double kMaxTravelMm = 100000.0, kMaxFeedMmMin = 600000.0, kMaxAccelMmS2 = 100000.0;
  dsp::WorkEnvelope e = defaults;
  static constexpr const char* kTravel[3] = {"travel_x_mm", "travel_y_mm", "travel_z_mm"};
  for (int i = 0; i < 3; ++i) {
    if (!t.has(kTravel[i])) continue;
    const auto v = t.numbers(kTravel[i], 2);
    if (!(v[0] < v[1])) t.fail(kTravel[i], "must be [min, max] with min below max");
    if (!(std::abs(v[0]) <= kMaxTravelMm && std::abs(v[1]) <= kMaxTravelMm))
      t.fail(kTravel[i], "must be within -100000..100000 mm");
    e.travel_mm[i][0] = v[0], e.travel_mm[i][1] = v[1];
  }
  e.max_feed_mm_min = t.number("max_feed_mm_min", e.max_feed_mm_min);
  if (!(e.max_feed_mm_min > 0.0 && e.max_feed_mm_min <= kMaxFeedMmMin))
    t.fail("max_feed_mm_min", "must be within (0, 600000] mm/min");
  e.max_accel_mm_s2 = t.number("max_accel_mm_s2", e.max_accel_mm_s2);
  if (!(e.max_accel_mm_s2 > 0.0 && e.max_accel_mm_s2 <= kMaxAccelMmS2))
    t.fail("max_accel_mm_s2", "must be within (0, 100000] mm/s^2");
  t.finish();
  return e;
}

}  // namespace eical::drivers
