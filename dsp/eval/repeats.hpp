#pragma once
// Repeat segmentation by the NC's triggers and averaging of N repeats (6-44).
//
// A calibration program marks every repeat with M102 (before each revolution, before each
// pass of a step or a rectangle). The stretches between consecutive marks whose set-point
// paths coincide — relative to where each begins, within one sample of motion — are
// repeats of one segment. The deviation measured − commanded is averaged sample by sample
// across them: the noise falls as 1/√N while the machine's systematic deviation stays,
// and the spread across them is the repeatability (what the thesis quotes as scatter).
#include "dsp/core/sample_rate.hpp"
#include "dsp/core/spill.hpp"

#include <Eigen/Core>

#include <cstdint>
#include <memory>
#include <vector>

namespace eical::dsp::eval {

struct RepeatGroup {
  std::vector<std::int64_t> first_index;  // sample index where each repeat begins
  std::size_t samples = 0;                // common length
  // Per sample of the segment, or every `stride`-th one (long runs evaluated as they
  // stream keep what a plot shows; the RMS figures are over every sample).
  std::vector<Eigen::Vector3d> mean_deviation_um;
  std::vector<Eigen::Vector3d> spread_um;  // sample standard deviation across the repeats
  std::size_t stride = 1;
  bool axis_moves[3] = {false, false, false};  // the set-point moves along it in the segment
  double scatter_rms_um = 0.0;                 // RMS over the segment of the spread, over the moving axes
  double mean_rms_um = 0.0;                    // RMS of the mean deviation, over the moving axes
  [[nodiscard]] int repeats() const noexcept { return static_cast<int>(first_index.size()); }
};

struct RepeatInput {
  const std::vector<std::int64_t>* sample_index = nullptr;
  const std::vector<Eigen::Vector3d>* pos_mm = nullptr;  // measured
  const std::vector<Eigen::Vector3d>* cmd_mm = nullptr;  // commanded
  std::vector<std::int64_t> marks;                       // M102 sample indices
  double fs_hz = kDefaultFs_hz;
};

// Groups of at least two repeats, largest first. Segments that are not contiguous in the
// trace (lost frames) or not covered by it are left out.
std::vector<RepeatGroup> average_repeats(const RepeatInput& in);

// The grouping as the trace goes by: it needs the set-point only, so the streamed
// analysis decides it in its first pass. Every trace sample in order, then finish().
class RepeatFinder {
 public:
  explicit RepeatFinder(std::vector<std::int64_t> marks);  // the M102 marks (any order)
  // A further mark, as the frames go by (ascending, before the trace sample it falls on).
  void mark(std::int64_t sample_index) { marks_.push_back(sample_index); }
  void add(std::size_t position, std::int64_t sample_index, const Eigen::Vector3d& cmd_mm);
  void finish();  // the trace ended (segments still open are not covered by it)

  struct Group {
    std::vector<std::size_t> begin;         // trace position of each repeat, in order
    std::vector<std::int64_t> first_index;  // its sample index
    std::size_t len = 0;                    // common length
    bool axis_moves[3] = {false, false, false};
  };
  // Groups of at least two, in the order of their first segment.
  [[nodiscard]] std::vector<Group> groups() const;

 private:
  struct Segment {
    std::size_t begin = 0;
    std::int64_t first_index = 0;
    std::size_t len = 0;  // samples so far (final when closed)
    bool contiguous = true;
    std::vector<Eigen::Vector3d> every7;  // the set-point at offsets 0, 7, 14, …
    std::vector<double> max_step;         // [i]: largest set-point step over offsets 1..i
    Eigen::Vector3d last = Eigen::Vector3d::Zero();
    std::size_t first_move[3] = {SIZE_MAX, SIZE_MAX, SIZE_MAX};  // first offset that moved along each axis
  };
  struct Leader {
    Segment seg;
    std::size_t len = 0;           // the group's common length so far
    std::vector<Segment> members;  // after the leader (only begin, first_index used)
  };
  void close(std::size_t position);
  void open(std::size_t position, std::int64_t sample_index);
  [[nodiscard]] bool same_path(const Segment& a, const Segment& b, std::size_t len) const;

  std::vector<std::int64_t> marks_;
  std::size_t next_mark_ = 0;
  bool has_open_ = false;
  Segment open_;
  std::int64_t prev_index_ = 0;
  std::vector<Leader> leaders_;
};

// The averaging as the trace goes by: add() every trace sample in order (the deviation
// measured − commanded of repeat samples is kept in a spill), then result() reads the
// spill once more for the spread. `keep`: the most points per group kept in the arrays.
class RepeatAverager {
 public:
  RepeatAverager(std::vector<RepeatFinder::Group> groups, std::unique_ptr<Spill> spill, std::size_t keep = SIZE_MAX);
  void add(std::size_t position, const Eigen::Vector3d& pos_mm, const Eigen::Vector3d& cmd_mm);
  [[nodiscard]] std::vector<RepeatGroup> result();

 private:
  std::vector<RepeatFinder::Group> groups_;
  std::unique_ptr<Spill> spill_;
  std::unique_ptr<SpillWriter<Doubles<3>>> writer_;
  std::size_t keep_;
  std::vector<std::vector<Eigen::Vector3d>> mean_;  // per group and offset
  // The repeat the next sample may fall in: group and member, in time order.
  std::vector<std::pair<std::size_t, std::size_t>> order_;  // (group, member) sorted by begin
  std::size_t next_ = 0;
};

}  // namespace eical::dsp::eval
