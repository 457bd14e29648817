#include "tools/plan/psd_layouts.hpp"

#include "dsp/core/error.hpp"

namespace eical::tools::plan {

namespace {

using enum sim::StripFacing;
constexpr PsdLayout kPsdLayouts[] = {{"none", 0, along_path}, {"B", 2, along_path},    {"B4", 4, along_path},
                                     {"B8", 8, along_path},   {"B16", 16, along_path}, {"R4", 4, across_path},
                                     {"R8", 8, across_path},  {"R16", 16, across_path}};

}  // namespace

const std::vector<std::string>& psd_layout_names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> v;
    for (const PsdLayout& l : kPsdLayouts) v.emplace_back(l.name);
    return v;
  }();
  return names;
}

PsdLayout psd_layout(const std::string& name) {
  for (const PsdLayout& l : kPsdLayouts)
    if (name == l.name) return l;
  std::string names;
  for (const std::string& n : psd_layout_names()) names += (names.empty() ? "" : ", ") + n;
  throw dsp::InputError("--psd '" + name + "': one of " + names);
}

}  // namespace eical::tools::plan
