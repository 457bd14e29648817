#pragma once
// A quality flag of a result: a code with its severity, the figure it concerns and the
// detail its text carries (counts, limits, the cause). Every decision — the verdict, which
// null a flag explains, what a report highlights — reads the code; the text is rendered
// once, where a result leaves the program (result JSON, report, DDS, log).
#include <cstdint>
#include <string>
#include <vector>

namespace eical::dsp {

// What a reader must not miss (the measurement is wrong or incomplete), what limits it,
// and what only explains a figure that is absent.
enum class FlagSeverity : std::uint8_t { critical, warning, note };

enum class FlagCode : std::uint8_t {
  // The pipeline's quality bits, in their bit order (pipeline.hpp, quality_flag).
  accel_missing,
  accel_saturated,
  frames_lost,
  not_finite,
  no_start_trigger,
  no_motion,
  short_rest_window,
  no_zupt_window,
  capacity_exceeded,
  no_end_trigger,
  fixed_saturated,
  supports_diverged,
  psd_disagrees,
  // The acquisition as the service saw it.
  interrupted,              // the service stopped during the measurement
  source_stopped,           // the source ended or failed during it
  source_rate,              // the source delivered another rate than configured
  recorder_overflow,        // frames analysed but not recorded
  temperature,              // a sensor outside its compensated temperature range
  setpoint,                 // the set-point could not be reconstructed as configured
  evaluated_after_restart,  // evaluated at the next start, without the service's own flags
  // What holds the position, and which channels can be trusted.
  position_unsupported,  // nothing holds the double integral: no position figure
  channel_untrusted,     // a channel the program needs is faulty or its strip's fixes are
  channel_unused,        // a faulty channel the program does not use
  truncated,             // the recording ends before its program
  noise_density,         // the rest noise disagrees with the data sheet
  // The program's evaluation (figure: the program object or the figure's key).
  evaluation_failed,  // the program could not be evaluated
  one_direction,      // a two-direction program with one direction found
  outside_standard,   // evaluated, but outside what the standard prescribes
  figure_null,        // one figure could not be determined
  circle_reference,   // the reference channel's circle could not be evaluated
  path_deviation,     // the contour deviation could not be evaluated
  unknown_program,    // no evaluation of this program kind (figure: the kind)
};

struct Flag {
  FlagCode code;
  std::string figure;  // result key or program object it concerns; empty when none
  std::string detail;  // what the text says after the code's words; empty: the code's default

  friend bool operator==(const Flag&, const Flag&) = default;
};

FlagSeverity severity(FlagCode code);
inline FlagSeverity severity(const Flag& f) { return severity(f.code); }
const char* code_name(FlagCode code);  // result.json's quality.flag_codes
const char* severity_name(FlagSeverity s);

// The flag as a reader reads it ("frames_lost: …", "step.settling_s: null, …").
std::string flag_text(const Flag& f);
std::vector<std::string> flag_texts(const std::vector<Flag>& flags);

bool has_flag(const std::vector<Flag>& flags, FlagCode code);
const Flag* find_flag(const std::vector<Flag>& flags, FlagCode code);
// A critical flag among them.
bool any_critical(const std::vector<Flag>& flags);

}  // namespace eical::dsp
