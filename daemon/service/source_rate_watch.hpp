#pragma once
// Does the source deliver samples at the rate [acquisition] fs_hz says? A DAQ running at
// another rate than configured, or a bridge replaying a recording faster than real time,
// gives frames that look fine one by one while every time, speed and length computed from
// them is wrong. The acquisition stamps (sample index, CLOCK_MONOTONIC when the
// acquisition thread had it) over the last kWindowS give the delivered rate; beyond
// kTolerance it is reported (Status.fault, the measurements flagged source_rate). Only
// live sources are watched (offline ones run as fast as they can by design); a source
// slower than fs_hz only when it is a DAQ (a simulator on a loaded machine may lag).
#include <cstdint>
#include <deque>
#include <utility>

namespace eical::daemon {

class SourceRateWatch {
 public:
  static constexpr double kWindowS = 4.0;     // bursts of a USB transfer or a pipe average out
  static constexpr double kTolerance = 0.05;  // a crystal is 1e-4 off; 5 % is another rate

  SourceRateWatch(double fs_hz, bool check_slow) : fs_hz_(fs_hz), check_slow_(check_slow) {}
  // Status thread, each tick: the last stamp seen. Delivered rate / fs_hz when off by more
  // than kTolerance over a full window; 0 when within or not known yet.
  double observe(std::int64_t sample_index, std::int64_t t_ns);
  // The source was reopened (its stamps start again).
  void reset() { window_.clear(); }

 private:
  double fs_hz_;
  bool check_slow_;
  std::deque<std::pair<std::int64_t, std::int64_t>> window_;  // (t_ns, sample index)
};

}  // namespace eical::daemon
