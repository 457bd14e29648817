#include "daemon/service/frame_loop.hpp"

#include "daemon/service/hmi_link.hpp"

#include <algorithm>
#include <cmath>

namespace eical::daemon {

FrameLoop::FrameLoop(const FrameLoopOptions& options, drivers::StampedSource& source, dsp::MeasurementSession& session,
                     dsp::Pipeline& live, FrameGuard& guard, RecordingHandoff& handoff, ServiceCounters& counters,
                     HmiLink* hmi)
    : options_(options),
      source_(source),
      session_(session),
      live_(live),
      guard_(guard),
      handoff_(handoff),
      counters_(counters),
      hmi_(hmi),
      // 2 s windows of the minimum filter, as for the servo clock.
      daq_clock_(1.0 / options.fs_hz, static_cast<std::int64_t>(2.0 * options.fs_hz)) {}

void FrameLoop::add_channel(TriggerChannel& channel) {
  if (n_channels_ < channels_.size()) channels_[n_channels_++] = &channel;
}

void FrameLoop::on_frame(const dsp::Frame& in) noexcept {
  dsp::Frame f = in;
  continue_clock(f);
  filter_frame_trigger(f);
  const bool nonfinite = guard_.apply(f);
  const std::int64_t acquired_ns = observe_acquisition(in);
  gate_.on_frame(f.sample_index);
  take_external_triggers(f);
  session_.on_frame(f);
  track_measurement(nonfinite);
  step_live(f);
  publish_live(f, acquired_ns);
  hand_over_if_ready();
  publish_counters(f);
}

void FrameLoop::continue_clock(dsp::Frame& f) noexcept {
  f.sample_index += index_offset_;
  if (gap_after_reopen_) f.flags |= dsp::frame_flag::gap_before, gap_after_reopen_ = false;
  last_index_ = f.sample_index;
}

void FrameLoop::filter_frame_trigger(dsp::Frame& f) const noexcept {
  // Without the "frame" input the DAQ's trigger channel is ignored (the NC sends its
  // M-codes another way; a floating trigger line must not start measurements).
  if (!options_.frame_triggers) f.trigger = 0;
}

std::int64_t FrameLoop::observe_acquisition(const dsp::Frame& in) noexcept {
  const std::int64_t acquired_ns = source_.acquired_ns(in.sample_index);
  const auto& stamp = source_.current_stamp();
  if (acquired_ns != 0 && stamp.last_index != stamp_seen_) {
    stamp_seen_ = stamp.last_index;
    daq_clock_.observe(stamp.last_index + index_offset_, stamp.t_ns);
    counters_.stamp_index.store(stamp.last_index + index_offset_, std::memory_order_relaxed);
    counters_.stamp_ns.store(stamp.t_ns, std::memory_order_relaxed);
  }
  return acquired_ns;
}

void FrameLoop::take_external_triggers(const dsp::Frame& f) noexcept {
  for (std::size_t c = 0; c < n_channels_; ++c) {
    TriggerRequest r;
    while (channels_[c]->take_request(r)) {
      // Its CLOCK_MONOTONIC time onto the DAQ clock; never before this frame.
      const double at = r.time_ns > 0 ? daq_clock_.number_at(r.time_ns) : std::nan("");
      if (std::isfinite(at) && at - static_cast<double>(f.sample_index) > kMaxTriggerAheadS * options_.fs_hz) {
        TriggerVerdict v;
        v.id = r.id, v.refusal = Refusal::time_ahead, v.sample_index = f.sample_index,
        v.state = session_.state().state();
        channels_[c]->answer(v);
        continue;
      }
      const std::int64_t idx =
          std::isfinite(at) ? std::max(static_cast<std::int64_t>(std::llround(at)), f.sample_index) : f.sample_index;
      TriggerVerdict v = gate_.decide(r, idx, session_.state().state());
      if (v.accepted && !session_.queue_trigger(idx, r.code)) v.accepted = false, v.refusal = Refusal::queue_full;
      if (v.accepted && r.code == kProgramStart) requested_p_ = r.p;
      channels_[c]->answer(v);
    }
  }
}

void FrameLoop::track_measurement(bool nonfinite) noexcept {
  const auto& k = session_.counters();
  if (k.measurements_started != started_seen_) {
    // A new measurement: its notes start afresh; M101 from the frame channel has no P word.
    started_seen_ = k.measurements_started;
    notes_ = RecordingNotes{};
    notes_.program_p = requested_p_;
    notes_.index_offset = index_offset_;
    requested_p_ = std::nan("");
  }
  if (session_.state().state() != dsp::State::measuring) return;
  if (nonfinite) ++notes_.nonfinite_frames;
  // The farthest the source's rate was off during the measurement.
  const double r = counters_.source_rate_ratio.load(std::memory_order_relaxed);
  if (r != 0.0 && std::abs(r - 1.0) > std::abs(notes_.source_rate_ratio - 1.0)) notes_.source_rate_ratio = r;
}

void FrameLoop::step_live(const dsp::Frame& f) noexcept {
  if (session_.state().state() == dsp::State::measuring || f.trigger == kProgramEnd) live_.step(f);
}

void FrameLoop::publish_live(const dsp::Frame& f, std::int64_t acquired_ns) noexcept {
  ++frames_;
  if (!hmi_ || frames_ % options_.live_every != 0) return;
  const auto& l = live_.live();
  hmi_->push_live({f.sample_index,
                   {l.pos_mm.x(), l.pos_mm.y(), l.pos_mm.z()},
                   {l.vel_mm_s.x(), l.vel_mm_s.y(), l.vel_mm_s.z()},
                   l.integrating,
                   acquired_ns});
}

void FrameLoop::hand_over_if_ready() noexcept {
  if (!session_.measurement_ready()) return;
  if (!handoff_.offer(session_, notes_)) {
    counters_.handoffs_deferred.fetch_add(1, std::memory_order_relaxed);  // the evaluator still holds the previous one
    return;
  }
  session_.evaluation_done();
  live_.reset();  // ready for the next M101, storage kept
}

void FrameLoop::publish_counters(const dsp::Frame& f) noexcept {
  const auto& k = session_.counters();
  constexpr auto relaxed = std::memory_order_relaxed;
  counters_.frames.store(k.frames, relaxed);
  counters_.frames_lost.store(k.frames_lost, relaxed);
  counters_.frames_flagged.store(k.frames_flagged, relaxed);
  counters_.bad_frames.store(guard_.bad_frames(), relaxed);
  counters_.measurements_started.store(k.measurements_started, relaxed);
  counters_.measurements.store(k.measurements_completed, relaxed);
  counters_.triggers_refused.store(k.triggers_refused, relaxed);
  counters_.triggers_late.store(k.triggers_late, relaxed);
  counters_.trigger_queue_full.store(k.trigger_queue_full, relaxed);
  counters_.recorder_overflow.store(session_.recorder_overflow(), relaxed);
  counters_.state.store(static_cast<int>(session_.state().state()), relaxed);
  counters_.sample_index.store(f.sample_index, relaxed);
  counters_.temp_c[0].store(f.temp_c[0], relaxed);
  counters_.temp_c[1].store(f.temp_c[1], relaxed);
}

void FrameLoop::continue_after_reopen() noexcept {
  source_.reset_lookup();
  stamp_seen_ = -1;
  index_offset_ = last_index_ + 1;
  gap_after_reopen_ = true;
  live_.reset();
}

void FrameLoop::close_measurement(const dsp::Flag& cause) {
  if (session_.close_now() || session_.measurement_ready()) {
    if (handoff_.offer_waiting(session_, notes_, cause)) session_.evaluation_done(), live_.reset();
  }
  // No frame follows to publish them: the last Status counts the measurement cut short.
  counters_.measurements_started.store(session_.counters().measurements_started, std::memory_order_relaxed);
  counters_.measurements.store(session_.counters().measurements_completed, std::memory_order_relaxed);
  counters_.state.store(static_cast<int>(session_.state().state()), std::memory_order_relaxed);
}

}  // namespace eical::daemon
