#pragma once
// What the DSP thread knows about a recording that its frames do not say.
#include <cmath>
#include <cstdint>

namespace eical::daemon {

struct RecordingNotes {
  std::uint64_t nonfinite_frames = 0;  // frames whose NaN/Inf channels the guard replaced
  double program_p = std::nan("");     // M101's P word (program number); NaN = none given
  std::int64_t index_offset = 0;       // added to the source's sample indices (after reopens)
  double source_rate_ratio = 0.0;      // the source's delivered rate / fs_hz while off (0: never off)
};

}  // namespace eical::daemon
