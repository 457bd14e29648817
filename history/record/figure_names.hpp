#pragma once
// What a figure's key says about it: its unit (from the key's suffix, results.md: "units
// are in the key names") and a label for people ("diagnostics.backlash_x_um" → "backlash X").
#include <string>

namespace eical::history {

// "µm", "ms", "µrad", "ppm", "s", "mm", "°", "Hz", "mm/min"; "" when the key names none.
std::string unit_of(const std::string& figure);

// The key without section and unit, words separated, axis letters upper case.
std::string label_of(const std::string& figure);

// RFC 3339 text (any offset, optional fraction, 'T' or ' ') as UTC "YYYY-MM-DDTHH:MM:SSZ";
// a local time without an offset is taken as UTC. "" when the text is not a date-time.
std::string utc_rfc3339(const std::string& text);

}  // namespace eical::history
