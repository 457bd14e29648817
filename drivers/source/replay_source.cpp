#include "drivers/source/replay_source.hpp"

#include <algorithm>
#include <thread>

namespace eical::drivers {

ReplaySource::ReplaySource(std::shared_ptr<const dsp::Run> run, Pacing pacing, std::string name)
    : run_(std::move(run)), pacing_(pacing), name_(std::move(name)) {
  if (!run_) throw SourceError(name_ + ": no run to replay");
}

void ReplaySource::open() {
  if (run_->frames.empty()) throw SourceError(name_ + ": run '" + run_->meta.id + "' has no samples");
  next_ = 0;
  start_ = std::chrono::steady_clock::now();
}

std::size_t ReplaySource::read(std::span<dsp::Frame> out) {
  if (next_ == 0) start_ = std::chrono::steady_clock::now();  // paced from the first read, as a DAQ streams
  const std::size_t left = run_->frames.size() - next_;
  std::size_t n = std::min(out.size(), left);
  if (pacing_ == Pacing::realtime && n > 0) {
    // Release frames when their sample time has come, as a DAQ delivering blocks would.
    const double fs_hz = run_->meta.acquisition.fs_hz;
    const auto first_index = run_->frames[next_].sample_index - run_->frames.front().sample_index;
    const auto last_due =
        start_ + std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(
                     static_cast<double>(first_index + static_cast<std::int64_t>(n)) / fs_hz));
    std::this_thread::sleep_until(last_due);
  }
  std::copy_n(run_->frames.begin() + static_cast<std::ptrdiff_t>(next_), n, out.begin());
  next_ += n;
  return n;
}

}  // namespace eical::drivers
