#pragma once
// One DAQ sample of everything eical acquires: the ring payload between drivers and the
// DSP pipeline. Trivially copyable, integer ADC counts (PX4 FIFOSample style); Eigen types
// appear only after the DSP boundary.
#include <cstdint>
#include <limits>
#include <type_traits>

namespace eical::dsp {

inline constexpr int kMaxPsd = 16;        // PSD strips per machine (i1, i2 each)
inline constexpr int kAccelChannels = 6;  // table ax, ay, az, head ax, ay, az

enum class Sensor : int { table = 0, head = 1 };

// Bits in Frame::flags: what is wrong with this sample. A flagged sample is still
// recorded; the pipeline decides whether the result is degraded.
namespace frame_flag {
inline constexpr std::uint32_t accel_missing = 1u << 0;    // an accel field was empty
inline constexpr std::uint32_t accel_saturated = 1u << 1;  // ADC at full scale
inline constexpr std::uint32_t psd_missing = 1u << 2;
inline constexpr std::uint32_t temp_missing = 1u << 3;
inline constexpr std::uint32_t cmd_missing = 1u << 4;
inline constexpr std::uint32_t gap_before = 1u << 5;     // frames were lost before this one
inline constexpr std::uint32_t not_finite = 1u << 6;     // NaN/Inf in a float channel
inline constexpr std::uint32_t table_missing = 1u << 7;  // a table accel field was empty (accel_missing set too)
inline constexpr std::uint32_t head_missing = 1u << 8;   // a head accel field was empty (accel_missing set too)
// The missing-field bit of sensor s (0 table, 1 head).
constexpr std::uint32_t sensor_missing(int s) { return s == 0 ? table_missing : head_missing; }
}  // namespace frame_flag

// NC trigger codes in Frame::trigger: the calibration program's M-functions.
namespace trigger {
inline constexpr std::int32_t none = 0;
inline constexpr std::int32_t program_start = 101;  // M101: tare, then measure
inline constexpr std::int32_t segment_mark = 102;   // M102: a segment ends (standstill, target reached)
inline constexpr std::int32_t program_end = 103;    // M103: stop and evaluate
constexpr bool is_nc_trigger(std::int32_t code) {
  return code == program_start || code == segment_mark || code == program_end;
}
}  // namespace trigger

struct Frame {
  std::int64_t sample_index = 0;                   // on the DAQ clock; time = index / fs_hz
  std::int32_t accel_counts[kAccelChannels] = {};  // sensor axes 1..3 of table, then head
  std::int32_t psd_counts[2 * kMaxPsd] = {};       // psd k: [2k] = i1, [2k+1] = i2 (DAQ counts)
  float temp_c[2] = {};                            // case temperature table, head (slow)
  double cmd_mm[3] = {};                           // NC set-point of the relative position
  double ref_mm[3] = {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::quiet_NaN(),
                      std::numeric_limits<double>::quiet_NaN()};  // reference; NaN = none
  std::int32_t trigger = 0;                                       // NC trigger code, 0 = none
  std::uint32_t flags = 0;                                        // frame_flag bits
  std::uint32_t psd_missing_electrodes = 0;                       // bit e: psd_counts[e] was empty (frame_fields.hpp)
};

static_assert(std::is_trivially_copyable_v<Frame>);
static_assert(2 * kMaxPsd <= 32, "one bit per PSD electrode in psd_missing_electrodes");
// 16 strips' 32 electrodes take four cache lines; at 10 kHz that is 2.4 MB/s through the ring.
static_assert(sizeof(Frame) <= 256, "Frame should stay within four cache lines");

}  // namespace eical::dsp
