#include "dsp/core/flag.hpp"

#include <algorithm>
#include <array>

namespace eical::dsp {
namespace {

// How the text begins: the code's words, or the figure it concerns.
enum class Lead : std::uint8_t { words, figure, figure_null, program_kind };

struct CodeInfo {
  FlagCode code;
  const char* name;
  FlagSeverity severity;
  Lead lead;
  const char* words;           // Lead::words: the text before the detail
  const char* default_detail;  // the text when the flag has no detail of its own
};

using S = FlagSeverity;
// One row per code, in the enum's order (checked below).
constexpr std::array kCodes = {
    CodeInfo{FlagCode::accel_missing, "accel_missing", S::critical, Lead::words,
             "accel_missing: ", "acceleration samples missing (last value held)"},
    CodeInfo{FlagCode::accel_saturated, "accel_saturated", S::critical, Lead::words,
             "accel_saturated: ", "ADC at full scale (last valid value held)"},
    CodeInfo{FlagCode::frames_lost, "frames_lost", S::critical, Lead::words,
             "frames_lost: ", "the DAQ or driver lost frames (gap integrated with the last value)"},
    CodeInfo{FlagCode::not_finite, "not_finite", S::critical, Lead::words,
             "not_finite: ", "NaN or Inf in a sample (last valid value held)"},
    CodeInfo{FlagCode::no_start_trigger, "no_start_trigger", S::warning, Lead::words,
             "no_start_trigger: ", "no M101 (101) trigger; rest window taken from the start of the data"},
    CodeInfo{FlagCode::no_motion, "no_motion", S::critical, Lead::words, "no_motion: ", "the set-point never moved"},
    CodeInfo{FlagCode::short_rest_window, "short_rest_window", S::warning, Lead::words,
             "short_rest_window: ", "fewer than 0.05 s at rest before the motion (bias uncertain)"},
    CodeInfo{FlagCode::no_zupt_window, "no_zupt_window", S::warning, Lead::words,
             "no_zupt_window: ", "no rest after the motion (velocity drift not removed)"},
    CodeInfo{FlagCode::capacity_exceeded, "capacity_exceeded", S::critical, Lead::words,
             "capacity_exceeded: ", "the measurement is longer than the trace capacity (end cut off)"},
    CodeInfo{FlagCode::no_end_trigger, "no_end_trigger", S::warning, Lead::words,
             "no_end_trigger: ", "no M103 (103) trigger; the measurement ends with the data"},
    CodeInfo{FlagCode::fixed_saturated, "fixed_saturated", S::critical, Lead::words,
             "fixed_saturated: ", "the fixed-point path clamped a value outside its Q-format range"},
    CodeInfo{FlagCode::supports_diverged, "supports_diverged", S::critical, Lead::words, "supports_diverged: ",
             "the support fusion met values it cannot take (trace left as integrated, no ZUPT/NBS/CUPT)"},
    CodeInfo{FlagCode::psd_disagrees, "psd_disagrees", S::critical, Lead::words, "psd_disagrees: ",
             "the PSD readings contradict the integrated motion beyond their noise (sensor model off? run eical "
             "identify); fused without them"},
    CodeInfo{FlagCode::interrupted, "interrupted", S::critical, Lead::words,
             "interrupted: ", "the service stopped during the measurement"},
    CodeInfo{FlagCode::source_stopped, "source_stopped", S::critical, Lead::words,
             "source_stopped: ", "the source ended during the measurement"},
    // Its times, speeds and lengths are wrong.
    CodeInfo{FlagCode::source_rate, "source_rate", S::critical, Lead::words,
             "source_rate: ", "the source delivered another rate than configured"},
    // The analysis saw every frame; the recording lacks some.
    CodeInfo{FlagCode::recorder_overflow, "recorder_overflow", S::warning, Lead::words,
             "recorder_overflow: ", "frames were not recorded"},
    // Outside the range the compensation is specified for.
    CodeInfo{FlagCode::temperature, "temperature", S::warning, Lead::words,
             "temperature: ", "a sensor outside its temperature limits"},
    CodeInfo{FlagCode::setpoint, "setpoint", S::warning, Lead::words, "setpoint: ", "no set-point"},
    // Without the flags only the stopped service knew: whether it was cut short, non-finite
    // channels.
    CodeInfo{FlagCode::evaluated_after_restart, "evaluated_after_restart", S::warning, Lead::words,
             "evaluated_after_restart: ",
             "eicald stopped between writing this run and its result; evaluated at the next start, without the flags "
             "only the stopped service knew (cut short, non-finite channels)"},
    CodeInfo{FlagCode::position_unsupported, "position_unsupported", S::critical, Lead::words, "position: null, ",
             "nothing holds the integrated position"},
    CodeInfo{FlagCode::channel_untrusted, "channel", S::critical, Lead::words, "channel: ", "a channel is faulty"},
    CodeInfo{FlagCode::channel_unused, "channel_unused", S::warning, Lead::words,
             "channel_unused: ", "a channel the program does not use is faulty"},
    CodeInfo{FlagCode::truncated, "truncated", S::critical, Lead::words,
             "truncated: ", "the recording ends before its program does"},
    CodeInfo{FlagCode::noise_density, "noise_density", S::warning, Lead::words,
             "noise_density: ", "the white noise at rest disagrees with the data sheet"},
    CodeInfo{FlagCode::evaluation_failed, "evaluation_failed", S::critical, Lead::figure, nullptr,
             "could not be evaluated"},
    CodeInfo{FlagCode::one_direction, "one_direction", S::warning, Lead::figure, nullptr,
             "the program runs both directions but only one was found"},
    CodeInfo{FlagCode::outside_standard, "outside_standard", S::warning, Lead::figure, nullptr, "outside the standard"},
    CodeInfo{FlagCode::figure_null, "figure_null", S::note, Lead::figure_null, nullptr,
             "could not be determined from this run"},
    CodeInfo{FlagCode::circle_reference, "circle_reference", S::note, Lead::words,
             "circle reference: ", "the reference channel's circle could not be evaluated"},
    CodeInfo{FlagCode::path_deviation, "path_deviation", S::note, Lead::words,
             "path deviation: ", "the contour deviation could not be evaluated"},
    CodeInfo{FlagCode::unknown_program, "unknown_program", S::note, Lead::program_kind, nullptr,
             "no evaluation in this version"},
};

constexpr bool in_enum_order() {
  for (std::size_t i = 0; i < kCodes.size(); ++i)
    if (static_cast<std::size_t>(kCodes[i].code) != i) return false;
  return true;
}
static_assert(in_enum_order(), "kCodes: one row per FlagCode, in the enum's order");
static_assert(kCodes.size() == static_cast<std::size_t>(FlagCode::unknown_program) + 1, "kCodes: a row is missing");

const CodeInfo& info(FlagCode code) { return kCodes[static_cast<std::size_t>(code)]; }

}  // namespace

FlagSeverity severity(FlagCode code) { return info(code).severity; }

const char* code_name(FlagCode code) { return info(code).name; }

const char* severity_name(FlagSeverity s) {
  switch (s) {
    case FlagSeverity::critical: return "critical";
    case FlagSeverity::warning: return "warning";
    case FlagSeverity::note: return "note";
  }
  return "note";
}

std::string flag_text(const Flag& f) {
  const CodeInfo& c = info(f.code);
  const std::string detail = f.detail.empty() ? c.default_detail : f.detail;
  switch (c.lead) {
    case Lead::words: return c.words + detail;
    case Lead::figure: return f.figure + ": " + detail;
    case Lead::figure_null: return f.figure + ": null, " + detail;
    case Lead::program_kind: return "program kind '" + f.figure + "': " + detail;
  }
  return detail;
}

std::vector<std::string> flag_texts(const std::vector<Flag>& flags) {
  std::vector<std::string> out;
  out.reserve(flags.size());
  for (const Flag& f : flags) out.push_back(flag_text(f));
  return out;
}

const Flag* find_flag(const std::vector<Flag>& flags, FlagCode code) {
  const auto it = std::find_if(flags.begin(), flags.end(), [code](const Flag& f) { return f.code == code; });
  return it == flags.end() ? nullptr : &*it;
}

bool has_flag(const std::vector<Flag>& flags, FlagCode code) { return find_flag(flags, code) != nullptr; }

bool any_critical(const std::vector<Flag>& flags) {
  return std::any_of(flags.begin(), flags.end(), [](const Flag& f) { return severity(f) == FlagSeverity::critical; });
}

}  // namespace eical::dsp
