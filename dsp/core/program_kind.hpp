#pragma once
// Which calibration program a run carries ([program] kind in run-format.md). Every decision
// on the program — what to evaluate, which figures, what the NC, the plan and the simulator
// do — reads this code; the name is the run file's text, read and written at the edge.
#include <array>
#include <cstdint>
#include <optional>
#include <string_view>
#include <utility>

namespace eical::dsp {

enum class ProgramKind : std::uint8_t {
  step,         // a move to a target and its settling (end-position error)
  positioning,  // ISO 230-2 bidirectional positioning along one axis
  rectangle,    // a rectangle in a plane: the corners' errors
  circle,       // ISO 230-4 circular test (ballbar class)
  freeform,     // any contour: the deviation from the set-point
  identify,     // on-site identification: swings across the PSD strips
};

inline constexpr std::array<std::pair<ProgramKind, const char*>, 6> kProgramKindNames = {{
    {ProgramKind::step, "step"},
    {ProgramKind::positioning, "positioning"},
    {ProgramKind::rectangle, "rectangle"},
    {ProgramKind::circle, "circle"},
    {ProgramKind::freeform, "freeform"},
    {ProgramKind::identify, "identify"},
}};

// The run file's name of a kind ("circle").
constexpr const char* program_kind_name(ProgramKind kind) {
  for (const auto& [k, name] : kProgramKindNames)
    if (k == kind) return name;
  return "unknown";
}

// The kind a run file names; nullopt for a name no program has.
constexpr std::optional<ProgramKind> parse_program_kind(std::string_view name) {
  for (const auto& [k, text] : kProgramKindNames)
    if (std::string_view(text) == name) return k;
  return std::nullopt;
}

}  // namespace eical::dsp
