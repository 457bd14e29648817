#include "dsp/session/measurement_recorder.hpp"

#include <algorithm>
#include <utility>

namespace eical::dsp {

MeasurementRecorder::MeasurementRecorder(std::size_t capacity_frames, std::size_t pretrigger_frames,
                                         RecordingSink* sink)
    : capacity_(capacity_frames + pretrigger_frames), sink_(sink), pre_(std::max<std::size_t>(1, pretrigger_frames)) {
  if (!sink_) buffer_.reserve(capacity_);
  if (pretrigger_frames == 0) pre_.clear();
}

void MeasurementRecorder::record(const Frame& f) noexcept {
  if (size() >= capacity_) {
    ++overflow_;
  } else if (!sink_) {
    buffer_.push_back(f);  // within reserve: no allocation
  } else if (sink_->frame(f)) {
    ++streamed_;
  } else {
    ++overflow_;  // the sink had no room: lost, counted
  }
}

void MeasurementRecorder::push(const Frame& f) noexcept {
  if (complete_) {
    // A finished recording waits to be taken; frames meanwhile keep the pre-trigger
    // ring warm for the next measurement.
  } else if (recording_) {
    record(f);
    if (stopping_ && post_left_-- == 0) {
      recording_ = false;
      complete_ = true;
    }
    return;
  }
  if (pre_.empty()) return;
  pre_[pre_head_] = f;
  pre_head_ = (pre_head_ + 1) % pre_.size();
  pre_count_ = std::min(pre_count_ + 1, pre_.size());
}

void MeasurementRecorder::start() noexcept {
  if (complete_) return;  // the previous recording was not taken yet: the caller faults
  buffer_.clear();
  streamed_ = 0;
  if (sink_) sink_->begin();
  const std::size_t n = pre_.size();
  for (std::size_t k = 0; k < pre_count_; ++k) record(pre_[(pre_head_ + n - pre_count_ + k) % n]);
  pre_count_ = 0;
  recording_ = true;
  stopping_ = false;
}

void MeasurementRecorder::stop_after(std::size_t posttrigger_frames) noexcept {
  if (!recording_) return;
  if (posttrigger_frames == 0) {
    recording_ = false;
    complete_ = true;
    return;
  }
  stopping_ = true;
  post_left_ = posttrigger_frames - 1;
}

void MeasurementRecorder::discard() noexcept {
  if (sink_ && (recording_ || complete_)) sink_->discard();
  buffer_.clear();
  streamed_ = 0;
  recording_ = complete_ = stopping_ = false;
}

bool MeasurementRecorder::take_streamed() noexcept {
  if (!complete_ || !sink_) return false;
  streamed_ = 0;
  complete_ = false;
  return true;
}

bool MeasurementRecorder::take(std::vector<Frame>& spare) noexcept {
  if (!complete_ || sink_ || spare.capacity() < capacity_) return false;
  spare.clear();
  std::swap(buffer_, spare);
  complete_ = false;
  return true;
}

}  // namespace eical::dsp
