#include "tools/report/sections.hpp"

#include <array>
#include <utility>

namespace eical::tools::report {
namespace {

// Per ProgramKind, in the enum's order (the identification has no report sections of its
// own: `eical identify` writes the calibration).
using SectionsWriter = void (*)(const dsp::Run&, const dsp::Analysis&, Page&, CsvFiles&);
constexpr std::array<std::pair<dsp::ProgramKind, SectionsWriter>, 6> kSections = {{
    {dsp::ProgramKind::step, step_sections},
    {dsp::ProgramKind::positioning, positioning_sections},
    {dsp::ProgramKind::rectangle, rectangle_sections},
    {dsp::ProgramKind::circle, circle_sections},
    {dsp::ProgramKind::freeform, freeform_sections},
    {dsp::ProgramKind::identify, nullptr},
}};

}  // namespace

void program_sections(const dsp::Run& run, const dsp::Analysis& a, Page& page, CsvFiles& csv) {
  for (const auto& [kind, write] : kSections)
    if (kind == run.meta.program.kind && write) write(run, a, page, csv);
}

}  // namespace eical::tools::report
