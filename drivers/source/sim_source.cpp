#include "drivers/source/sim_source.hpp"

#include "sim/simulate.hpp"

#include <algorithm>
#include <cmath>
#include <thread>

namespace eical::drivers {

SimSource::SimSource(sim::Scenario scenario, SimSourceOptions options)
    : scenario_(std::move(scenario)), options_(options) {
  run_ = std::make_shared<const dsp::Run>(sim::simulate(scenario_, options_.keep_truth ? &truth_ : nullptr));
  const double fs = run_->meta.acquisition.fs_hz;
  idle_frames_ = options_.repeat ? static_cast<std::size_t>(std::llround(options_.idle_s * fs)) : 0;
  // Frames before the first trigger are at rest: the idle phase cycles through them.
  rest_frames_ = 1;
  while (rest_frames_ < run_->frames.size() && run_->frames[rest_frames_].trigger == 0) ++rest_frames_;
}

void SimSource::open() {
  pos_ = 0;
  next_index_ = 0;
  finished_ = false;
  start_ = std::chrono::steady_clock::now();
}

bool SimSource::at_end() const { return finished_; }

std::int64_t SimSource::sample_time_ns(std::int64_t sample_index) const {
  if (options_.pacing != Pacing::realtime) return 0;
  const double fs = run_->meta.acquisition.fs_hz;
  const auto start_ns = std::chrono::duration_cast<std::chrono::nanoseconds>(start_.time_since_epoch()).count();
  return start_ns + std::llround(static_cast<double>(sample_index) * 1e9 / fs);
}

std::size_t SimSource::read(std::span<dsp::Frame> out) {
  // The sample clock starts with the first read, as a DAQ streams from when it is read:
  // the time between open() and the acquisition thread's start is not caught up in a burst.
  if (next_index_ == 0) start_ = std::chrono::steady_clock::now();
  const std::size_t n_prog = run_->frames.size();
  std::size_t n = 0;
  while (n < out.size() && !finished_) {
    dsp::Frame f;
    if (pos_ < n_prog) {
      f = run_->frames[pos_];
    } else {
      f = run_->frames[(pos_ - n_prog) % rest_frames_];
      f.trigger = 0;
    }
    f.sample_index = next_index_++;
    out[n++] = f;
    if (++pos_ == n_prog + idle_frames_) {
      if (options_.repeat)
        pos_ = 0;
      else
        finished_ = true;
    }
  }
  if (options_.pacing == Pacing::realtime && n > 0) {
    const double fs = run_->meta.acquisition.fs_hz;
    std::this_thread::sleep_until(start_ + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                               std::chrono::duration<double>(static_cast<double>(next_index_) / fs)));
  }
  return n;
}

}  // namespace eical::drivers
