#pragma once
// What a figure's key says to people: a label ("diagnostics.backlash_x_um" → "backlash X");
// its unit is dsp::unit_of_key (dsp/core/key_unit.hpp).
#include <string>

namespace eical::history {

// The key without section and unit, words separated, axis letters upper case.
std::string label_of(const std::string& figure);

// RFC 3339 text (any offset, optional fraction, 'T' or ' ') as UTC "YYYY-MM-DDTHH:MM:SSZ";
// a local time without an offset is taken as UTC. "" when the text is not a date-time.
std::string utc_rfc3339(const std::string& text);

}  // namespace eical::history
