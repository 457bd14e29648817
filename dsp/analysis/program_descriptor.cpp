#include "dsp/analysis/program_descriptor.hpp"

#include "dsp/analysis/program_evaluations.hpp"

#include <array>
#include <cstddef>

namespace eical::dsp {
namespace {

// A rectangle moves one axis at a time: the other is held (NBS), the circle and free form
// move both. The limits are what each program must resolve ([docs/uncertainty.md],
// "Verdict"): a circle's G 10 µm (ISO 230-4's ballbar class), E 5 µm for ISO 230-2.
constexpr std::array<ProgramDescriptor, 6> kPrograms = {{
    {ProgramKind::step, ProgramMotion::along_axis, "step response", "Step response report",
     detail::evaluate_step_program,
     ResolutionLimit{"step.largest_step_measured_um", "the measured step", "step.end_position_error_um",
                     "the end-position error", 2.0},
     false},
    {ProgramKind::positioning, ProgramMotion::along_axis, "positioning (ISO 230-2)", "Positioning test report",
     detail::evaluate_positioning_program,
     ResolutionLimit{"positioning.A_um", "positioning accuracy A", "positioning.E_um", "E", 5.0}, false},
    {ProgramKind::rectangle, ProgramMotion::in_plane, "rectangle", "Rectangle test report",
     detail::evaluate_rectangle_program,
     ResolutionLimit{"rectangle.corner_error_max_um", "the largest corner error", "rectangle.corner_error_max_um",
                     "the corner error", 10.0},
     true},
    {ProgramKind::circle, ProgramMotion::in_plane, "circular test (ISO 230-4)", "Circular test report",
     detail::evaluate_circle_program,
     ResolutionLimit{"circle.circular_deviation_G_um", "circular deviation G", "circle.circular_deviation_G_um", "G",
                     10.0},
     false},
    {ProgramKind::freeform, ProgramMotion::in_plane, "free form", "Free-form contour report",
     detail::evaluate_freeform_program,
     ResolutionLimit{"freeform.contour_error_max_um", "the largest contour error", "freeform.contour_error_max_um",
                     "the contour error", 10.0},
     false},
    {ProgramKind::identify, ProgramMotion::swings, "identification", "Identification run report", nullptr, std::nullopt,
     false},
}};

// The table is in the enum's order, so a kind is its row's index.
constexpr bool in_kind_order() {
  for (std::size_t i = 0; i < kPrograms.size(); ++i)
    if (static_cast<std::size_t>(kPrograms[i].kind) != i) return false;
  return kPrograms.size() == kProgramKindNames.size();
}
static_assert(in_kind_order(), "kPrograms: one row per ProgramKind, in the enum's order");

}  // namespace

std::span<const ProgramDescriptor> program_descriptors() { return kPrograms; }

const ProgramDescriptor& program_descriptor(ProgramKind kind) { return kPrograms[static_cast<std::size_t>(kind)]; }

}  // namespace eical::dsp
