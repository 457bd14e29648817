#pragma once
// The measured path where the error field reads it (error_field.hpp): at the end of each
// coarse block (coarse_schedule.hpp) in the sensors' time, on the aligned trace — the
// position since the start, the velocity, the acceleration (central difference over one
// block) and the case temperatures since the start. A few values per coarse sample, so a
// streamed analysis collects them as its trace goes by (CoarsePathProbe) and a trace in
// memory is read by the same code (coarse_path()): the same numbers either way.
#include "dsp/uncertainty/coarse_schedule.hpp"

#include <Eigen/Core>

#include <cstddef>
#include <vector>

namespace eical::dsp::uncertainty {

struct CoarsePath {
  std::vector<Eigen::Vector3d> pos_mm, vel_mm_s, acc_mm_s2;  // per coarse sample; pos since the trace's start
  std::vector<Eigen::Vector2d> temp_c;                       // table, head since the start; empty: none
};

class CoarsePathProbe {
 public:
  // samples: the trace's length (reads beyond its ends take its first or last sample);
  // delay_samples: aligned trace position = sensor position − delay.
  CoarsePathProbe(const CoarseSchedule& coarse, double delay_samples, std::size_t samples, double fs_hz);

  // Trace sample k, in order from 0: aligned position and velocity, case temperatures.
  void sample(std::size_t k, const Eigen::Vector3d& pos_mm, const Eigen::Vector3d& vel_mm_s,
              const Eigen::Vector2d& temp_c) noexcept;

  // After the trace's last sample. with_temp: the temperatures were given.
  [[nodiscard]] CoarsePath path(bool with_temp) const;

 private:
  // A read at a fractional trace position: sample i0, or linear between i0 and i0 + 1.
  struct Read {
    std::size_t i0 = 0;
    double f = 0.0;
    bool between = false;
  };
  [[nodiscard]] Read read_at(double position) const noexcept;
  [[nodiscard]] std::size_t slot(std::size_t k) const;
  template <typename V>
  [[nodiscard]] V value(const std::vector<V>& x, const Read& r) const;

  const CoarseSchedule* coarse_;
  double delay_, fs_hz_;
  std::size_t samples_;
  std::vector<std::size_t> need_;  // trace samples read, ascending
  std::vector<Eigen::Vector3d> pos_, vel_;
  std::vector<Eigen::Vector2d> temp_;
  std::size_t next_ = 0;
};

// The same from a trace in memory (temp_c may be null: no temperatures).
CoarsePath coarse_path(const CoarseSchedule& coarse, double delay_samples, double fs_hz,
                       const std::vector<Eigen::Vector3d>& pos_mm, const std::vector<Eigen::Vector3d>& vel_mm_s,
                       const std::vector<Eigen::Vector2d>* temp_c);

}  // namespace eical::dsp::uncertainty
