#include "dsp/analysis/channel_findings.hpp"

#include "dsp/analysis/program_descriptor.hpp"
#include "dsp/core/axes.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace eical::dsp {
namespace {

// A sensor axis whose direction cosine on a machine axis is below this (about 3°) feeds it
// a mounting tolerance, not its motion.
constexpr double kAxisCoupling = 0.05;

const char* const kAxisName[3] = {"X", "Y", "Z"};

int axis_of(const std::string& a) { return std::max(0, axis_index(a)); }

std::string axes_text(unsigned axes) {
  std::string s;
  for (int i = 0; i < 3; ++i)
    if (axes & (1u << i)) s += (s.empty() ? "" : ", ") + std::string(kAxisName[i]);
  return s.empty() ? "none" : s;
}

std::string span_text(const health::Finding& f) {
  char b[160];
  if (f.spans > 1)
    std::snprintf(b, sizeof b, "in %d stretches from %.3f s to %.3f s (%lld samples in all)", f.spans, f.from_s, f.to_s,
                  static_cast<long long>(f.samples));
  else
    std::snprintf(b, sizeof b, "from %.3f s to %.3f s (%lld samples)", f.from_s, f.to_s,
                  static_cast<long long>(f.samples));
  return b;
}

// "table_ay stuck at 0 counts from 0.000 s to 6.283 s (62831 samples)"
std::string finding_text(const health::Finding& f) {
  const std::string name = health::channel_name(f.channel);
  char b[96];
  switch (f.fault) {
    case health::Fault::empty: return name + " empty: not one sample in the run";
    case health::Fault::missing: return name + " missing " + span_text(f);
    case health::Fault::stuck:
      std::snprintf(b, sizeof b, " stuck at %.0f counts ", f.value);
      return name + b + span_text(f);
    case health::Fault::dead:
      std::snprintf(b, sizeof b, " dead: σ at rest %.3f of the data sheet's noise ", f.value);
      return name + b + span_text(f);
    case health::Fault::clipped: return name + " clipped at the ADC's full scale " + span_text(f);
    case health::Fault::truncated: break;
  }
  return name;
}

bool measures_nothing(health::Fault f) {
  return f == health::Fault::empty || f == health::Fault::stuck || f == health::Fault::dead;
}

std::string program_text(const Program& p) {
  const std::string kind(program_kind_name(p.kind));
  switch (program_descriptor(p.kind).motion) {
    case ProgramMotion::along_axis: return "the " + kind + " along " + p.axis;
    case ProgramMotion::in_plane: return "the " + kind + " in " + p.plane;
    case ProgramMotion::swings: break;
  }
  return "the " + kind;
}

}  // namespace

unsigned program_axes(const Program& program) {
  switch (program_descriptor(program.kind).motion) {
    case ProgramMotion::in_plane: {
      const auto [a, b] = plane_axes(program.plane);
      return (1u << a) | (1u << b);
    }
    case ProgramMotion::along_axis: return 1u << axis_of(program.axis);
    case ProgramMotion::swings: break;
  }
  return 7u;
}

unsigned channel_axes(const RunMeta& meta, int c) {
  if (!health::is_accel(c)) return 0;
  unsigned axes = 0;
  for (int i = 0; i < 3; ++i)
    if (std::abs(meta.sensors[c / 3].to_machine(i, c % 3)) > kAxisCoupling) axes |= 1u << i;
  return axes;
}

bool judge_channels(const RunMeta& meta, const std::vector<health::Finding>& findings, Analysis& a) {
  const Program& p = meta.program;
  const unsigned needed = program_axes(p);
  unsigned unmeasured = 0;
  std::string unmeasured_why;
  for (const health::Finding& f : findings) {
    if (f.fault == health::Fault::truncated) {
      char b[200];
      std::snprintf(b, sizeof b,
                    "the recording ends at %.3f s before its program does: M101 (101) started it, no M103 (103) "
                    "ended it%s; the figures cover what was recorded",
                    f.to_s, f.set_point_moving ? ", the set-point still moving at the last sample" : "");
      a.flags.push_back({FlagCode::truncated, {}, b});
      a.degraded = true;
      continue;
    }
    const std::string what = finding_text(f);
    if (!health::is_accel(f.channel)) {  // a PSD electrode: its strip's fixes
      a.flags.push_back({FlagCode::channel_untrusted, {}, what + ": the fixes of its PSD strip are not to be trusted"});
      a.degraded = true;
      continue;
    }
    // The pipeline holds a sensor's three axes while a field of it is missing (the
    // frame's flag is the sensor's), both sensors at full scale: what the finding spoils.
    const int sensor = f.channel / 3;
    const char* sensor_name = sensor == 0 ? "table" : "head";
    unsigned axes = channel_axes(meta, f.channel);
    std::string whom = std::string(sensor_name) + " sensor axis " + std::to_string(f.channel % 3 + 1);
    if (f.fault == health::Fault::empty || f.fault == health::Fault::missing) {
      for (int c = 3 * sensor; c < 3 * sensor + 3; ++c) axes |= channel_axes(meta, c);
      whom = "the " + std::string(sensor_name) + " sensor, held without it";
    } else if (f.fault == health::Fault::clipped) {
      for (int c = 0; c < kAccelChannels; ++c) axes |= channel_axes(meta, c);
      whom = "both sensors, held while it clips";
    }
    whom += " (machine " + axes_text(axes) + ")";
    if (!(axes & needed)) {
      a.flags.push_back(
          {FlagCode::channel_unused, {}, what + ": " + whom + ", which " + program_text(p) + " does not use"});
      continue;
    }
    a.degraded = true;
    if (measures_nothing(f.fault)) {
      unmeasured |= axes & needed;
      unmeasured_why +=
          (unmeasured_why.empty() ? "" : ", ") + health::channel_name(f.channel) + " " + health::fault_code(f.fault);
      a.flags.push_back({FlagCode::channel_untrusted,
                         {},
                         what + ": " + whom + ", which " + program_text(p) + " needs, is not measured"});
    } else {
      a.flags.push_back({FlagCode::channel_untrusted,
                         {},
                         what + ": " + whom + ", which " + program_text(p) + " needs, at its last value there"});
    }
  }
  if (!unmeasured) return true;
  a.flags.push_back(
      {FlagCode::evaluation_failed, program_kind_name(p.kind),
       "null, not evaluated: machine " + axes_text(unmeasured) + " not measured (" + unmeasured_why + ")"});
  return false;
}

}  // namespace eical::dsp
