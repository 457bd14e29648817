#pragma once
// Time stamps as the history keys them. A figure's label and unit are dsp::label_of_key and
// dsp::unit_of_key (dsp/core/key_unit.hpp).
#include <string>

namespace eical::history {

// RFC 3339 text (any offset, optional fraction, 'T' or ' ') as UTC "YYYY-MM-DDTHH:MM:SSZ";
// a local time without an offset is taken as UTC. "" when the text is not a date-time.
std::string utc_rfc3339(const std::string& text);

}  // namespace eical::history
