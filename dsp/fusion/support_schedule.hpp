#pragma once
// Which supports hold at which sample of a measurement's trace: the input of the offline
// smoother, built from the same decisions the live filter makes (standstill detector, NBS
// from the set-point, PSD fixes), refined with hindsight (a standstill is known from its
// first quiet sample, not from the end of the detector's window).
#include <Eigen/Core>

#include <cstddef>
#include <cstdint>
#include <vector>

namespace eical::dsp::fusion {

namespace schedule_flag {
inline constexpr std::uint8_t rest = 1u << 0;        // ZUPT on every axis
inline constexpr std::uint8_t nbs_x = 1u << 1;       // NBS: axis held (bit 1 + axis)
inline constexpr std::uint8_t move_start = 1u << 4;  // a move begins: the bias may jump (ch. 8.3.2)
inline constexpr std::uint8_t invalid = 1u << 5;     // no valid acceleration: no velocity support
}  // namespace schedule_flag

inline constexpr std::uint8_t nbs_flag(int axis) { return static_cast<std::uint8_t>(schedule_flag::nbs_x << axis); }

// A position fix from a PSD strip: the relative position along `axis` at trace sample k.
struct PositionFix {
  std::size_t k = 0;
  int axis = 0;
  double position_um = 0.0;     // in the trace's frame (the set-point at the start)
  double sigma_um = 0.0;        // the strip's own noise
  int strip = 0;                // which PSD strip
  double model_sigma_um = 0.0;  // what the sensor model's uncertainty adds there (scale × distance)
  double way_mm = 0.0;          // the integrated way along `axis` from the start (the scale state's share)
  double vel_mm_s = 0.0;        // the integrated velocity along `axis` (the timing state's share)
};

// The mean integrated velocity over a window ending at sample k of a standstill where the
// machine still rings: δv_k − δb·lag is what it observes (the bias acts over the window).
struct VelocityMean {
  std::size_t k = 0;
  double mean_um_s[3] = {0, 0, 0};
  double sigma_um_s = 0.0;
  double lag_s = 0.0;  // from the window's mean time to sample k
};

struct SupportSchedule {
  std::vector<std::uint8_t> flags;  // one per trace sample
  std::vector<PositionFix> fixes;   // ascending k
  // Per trace sample when present: 0 — a standstill's velocity with the model's
  // zupt_sigma_um_s; negative — a ringing standstill, whose samples are not used one by one
  // (their swings are correlated) but through velocity_means.
  std::vector<float> zupt_sigma_um_s;
  std::vector<VelocityMean> velocity_means;  // ascending k
  // Where an axis' scale or timing is a state (reads_the_way): the integrated way from the
  // start per sample (mm; float: 0.1 µm in 1 m, times a scale error of 1e-3), the scale's
  // share of the position there, and by its differences the velocity, the timing's share.
  // Empty without such an axis.
  std::vector<Eigen::Vector3f> way_mm;
  bool zupt = true;  // off: standstills are found and reported, not used
  bool cupt = true;  // off: PSD fixes are recorded, not used

  // The velocity (mm/s) of the way between trace samples lo < hi that lie `steps` sample
  // periods apart (their true spacing: lost frames, a coarse grid); 0 without a span.
  [[nodiscard]] Eigen::Vector3d way_velocity_mm_s(std::size_t lo, std::size_t hi, std::int64_t steps,
                                                  double fs_hz) const {
    if (steps <= 0 || hi >= way_mm.size()) return Eigen::Vector3d::Zero();
    return (way_mm[hi] - way_mm[lo]).cast<double>() * (fs_hz / static_cast<double>(steps));
  }
};

}  // namespace eical::dsp::fusion
