#pragma once
// One calibration program as the analysis knows it: how its motion lies, how it is
// evaluated, what it must resolve, how its report is titled. Every program is one row of
// one table (program_descriptor.cpp); analyze, the verdict, the channel findings, the
// report and the plan read the row of the run's ProgramKind instead of comparing kinds.
// The kind's name in a run file stays with the enum (dsp/core/program_kind.hpp).
#include "dsp/analysis/analyze_run.hpp"
#include "dsp/core/program_kind.hpp"

#include <optional>
#include <span>

namespace eical::dsp {

// Where a program's motion lies: what its [program] axis or plane names.
enum class ProgramMotion : std::uint8_t {
  along_axis,  // one axis ([program] axis): step, positioning
  in_plane,    // two axes ([program] plane): circle, rectangle, free form
  swings,      // every axis it is told to swing (identification)
};

// What a program's verdict asks of its figures (verdict.hpp: judge).
struct ResolutionLimit {
  const char* headline;  // result key of the headline figure (must exceed its U)
  const char* name;      // as a user reads it
  const char* limited;   // result key whose U must stay within `limit`
  const char* limited_name;
  double limit;  // in the limited figure's unit (its key's suffix, dsp::unit_of_key)
};

struct ProgramDescriptor {
  ProgramKind kind;
  ProgramMotion motion;
  const char* title;         // its figures' heading, "circular test (ISO 230-4)"
  const char* report_title;  // "Circular test report"
  // Fills its part of the Analysis, or leaves it empty with the reason in its flags; never
  // throws. Null: analyze evaluates nothing (the identification: `eical identify` reads it).
  void (*evaluate)(const Run&, Analysis&, const EvaluationOptions&);
  std::optional<ResolutionLimit> resolution;  // none: no verdict on the figures' U
  bool nbs_by_default;                        // a held axis's velocity as a support (NBS) unless told otherwise
};

// Every program, one row each, in ProgramKind's order.
std::span<const ProgramDescriptor> program_descriptors();
// The row of a kind.
const ProgramDescriptor& program_descriptor(ProgramKind kind);

}  // namespace eical::dsp
