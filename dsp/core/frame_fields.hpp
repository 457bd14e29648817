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
// PSD electrode c (0..7: psd k i1 = 2k, i2 = 2k + 1).
constexpr std::uint32_t psd_field_missing(int c) { return 1u << (15 + c); }
inline constexpr std::uint32_t psd_fields_missing = 0xFFu << 15;  // any of them

static_assert(accel_field_missing(0) > head_missing, "the field bits follow frame.hpp's");

}  // namespace eical::dsp::frame_flag
