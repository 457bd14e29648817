#pragma once
// The one table of result-key suffixes and their units (result-format.md: "units are in
// the key names"): "circle.circular_deviation_G_um" is in µm. The verdict, the history,
// `eical analyze` and the report all read a figure's unit here. Header only, so that the
// history (a leaf library, docs/architecture.md) reads it without linking dsp.
#include <array>
#include <string>
#include <string_view>
#include <utility>

namespace eical::dsp {

namespace key_unit_detail {
// No suffix ends another ("x_ms" does not end in "_s"), so at most one matches.
inline constexpr std::array<std::pair<std::string_view, std::string_view>, 9> kUnits = {{{"_mm_min", "mm/min"},
                                                                                         {"_urad", "µrad"},
                                                                                         {"_ppm", "ppm"},
                                                                                         {"_deg", "°"},
                                                                                         {"_um", "µm"},
                                                                                         {"_mm", "mm"},
                                                                                         {"_ms", "ms"},
                                                                                         {"_hz", "Hz"},
                                                                                         {"_s", "s"}}};

constexpr const std::pair<std::string_view, std::string_view>* suffix_of(std::string_view key) {
  for (const auto& entry : kUnits)
    if (key.size() > entry.first.size() && key.substr(key.size() - entry.first.size()) == entry.first) return &entry;
  return nullptr;
}
}  // namespace key_unit_detail

// "µm", "ms", "µrad", "ppm", "s", "mm", "°", "Hz", "mm/min"; "" when the key names none.
inline std::string unit_of_key(std::string_view key) {
  const auto* e = key_unit_detail::suffix_of(key);
  return std::string(e != nullptr ? e->second : std::string_view{});
}

// The key without its unit suffix ("circle.circular_deviation_G_um" → "circle.circular_deviation_G").
inline std::string key_without_unit(std::string_view key) {
  const auto* e = key_unit_detail::suffix_of(key);
  return std::string(e != nullptr ? key.substr(0, key.size() - e->first.size()) : key);
}

// A figure as a person reads it: the key without its program and unit, words apart, an
// axis in capitals ("diagnostics.backlash_x_um" → "backlash X", "circle.circular_deviation_G_um"
// → "circular deviation G"). The report, analyze's text and the history all say it so.
inline std::string label_of_key(std::string_view key) {
  const std::size_t dot = key.find('.');
  const std::string bare = key_without_unit(dot == std::string_view::npos ? key : key.substr(dot + 1));
  std::string out;
  std::size_t start = 0;
  while (start <= bare.size()) {
    std::size_t end = bare.find_first_of("_.", start);
    if (end == std::string::npos) end = bare.size();
    std::string word = bare.substr(start, end - start);
    if (word == "x" || word == "y" || word == "z") word[0] = static_cast<char>(word[0] - 'a' + 'A');
    if (!word.empty()) out += (out.empty() ? "" : " ") + word;
    start = end + 1;
  }
  return out;
}

}  // namespace eical::dsp
