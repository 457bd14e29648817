#pragma once
// Which field of a frame was empty, where the source knows it (the run reader does): more
// bits of Frame::flags (frame.hpp), beside the sensor's table_missing / head_missing and
// psd_missing it sets as well. A frame with a sensor's bit and none of its fields' names no
// field (the whole triplex, as sources that cannot tell write it).
#include "dsp/core/frame.hpp"

#include <cstdint>

namespace eical::dsp::frame_flag {

// Accel channel c (0..5: table ax, ay, az, head ax, ay, az).
constexpr std::uint32_t accel_field_missing(int c) { return 1u << (9 + c); }
constexpr std::uint32_t sensor_fields_missing(int s) {
  return accel_field_missing(3 * s) | accel_field_missing(3 * s + 1) | accel_field_missing(3 * s + 2);
}
// PSD electrode e (psd k i1 = 2k, i2 = 2k + 1) has its own bit in
// Frame::psd_missing_electrodes: 16 strips' 32 electrodes do not fit beside the flags.
constexpr bool psd_field_missing(const Frame& f, int e) { return (f.psd_missing_electrodes >> e) & 1u; }
constexpr bool psd_fields_named(const Frame& f) { return f.psd_missing_electrodes != 0; }
// Whether electrode e's count is absent: by its own bit where the source names the empty
// electrodes, else by psd_missing (every electrode of that sample).
constexpr bool psd_electrode_empty(const Frame& f, int e) {
  return psd_fields_named(f) ? psd_field_missing(f, e) : (f.flags & psd_missing) != 0;
}
constexpr void mark_psd_field_missing(Frame& f, int e) {
  f.flags |= psd_missing;
  f.psd_missing_electrodes |= 1u << e;
}

static_assert(accel_field_missing(0) > head_missing, "the field bits follow frame.hpp's");

}  // namespace eical::dsp::frame_flag
