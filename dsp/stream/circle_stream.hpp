#pragma once
// The circular test evaluated as the corrected trace goes by (the streamed analysis):
// what detail::evaluate_circle_program() does over a stored trace, in the same order and
// with the same accumulators — each revolution fitted when it ends (one revolution in
// memory), H from 1° bins, the reference channel beside the measured one, the
// diagnostics' passes into spills read back three times.
#include "dsp/analysis/analyze_run.hpp"
#include "dsp/core/spill.hpp"
#include "dsp/eval/circle.hpp"
#include "dsp/eval/circle_segments.hpp"

#include <Eigen/Core>

#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace eical::dsp {

class CircleStream {
 public:
  // From the first pass: the stretches found (or why none could be), whether the
  // reference channel is usable (present and finite over the trace).
  CircleStream(const Run& run, std::vector<eval::CircleSegment> segments, std::optional<std::string> segment_error,
               bool reference, const SpillFactory& spills);
  // Every corrected trace sample, in order.
  void sample(std::int64_t sample_index, const Eigen::Vector3d& pos_mm, const Eigen::Vector3d& cmd_mm,
              const Eigen::Vector3d& ref_mm);
  // The figures and flags into the analysis (as evaluate_circle_program() puts them).
  void finish(Analysis& a);

 private:
  struct Range {
    std::int64_t first = 0, second = 0;
    int dir = 0;  // 0 ccw, 1 cw
    std::size_t samples = 0;
  };
  struct Channel {  // the measured or the reference positions
    std::optional<eval::CircleAccumulator> acc[2];
    std::optional<std::string> error;
  };
  void enter(const Range& r);
  void leave(const Range& r);

  const Run& run_;
  int ia_ = 0, ib_ = 1;
  std::vector<Range> ranges_;  // time order
  std::vector<Range> by_dir_[2];
  std::optional<std::string> segment_error_;
  bool reference_ = false;
  Channel meas_, ref_;
  std::size_t next_ = 0;  // first range not yet left
  bool inside_ = false;
  double accuracy_ss_ = 0.0;
  std::size_t accuracy_n_ = 0;
  // Diagnostics: one pass per direction, from its first mark to its last.
  std::unique_ptr<Spill> pass_spill_[2];
  std::unique_ptr<SpillWriter<Doubles<4>>> pass_writer_[2];
  std::size_t pass_samples_[2] = {0, 0};
};

}  // namespace eical::dsp
