#pragma once
// eicald's per-frame path on the DSP thread, as a flat list of stages: continue the DAQ
// clock across a reopened source, keep or drop the frame's own trigger, replace non-finite
// channels, map external triggers (DDS, GPIO, CAN) onto the DAQ clock and decide on them,
// run the measurement session and the live pipeline, hand Live samples to the HMI
// publisher, hand a finished recording to the evaluation thread, and publish the counters.
// Nothing here allocates, locks, waits or writes a stream (tests/daemon counts the
// allocations of a whole measurement through it).
#include "daemon/service/frame_guard.hpp"
#include "daemon/service/recording_handoff.hpp"
#include "daemon/service/service_counters.hpp"
#include "daemon/triggers/trigger_channel.hpp"
#include "daemon/triggers/trigger_gate.hpp"
#include "drivers/source/sample_clock.hpp"
#include "drivers/source/stamped_source.hpp"
#include "dsp/core/sample_rate.hpp"
#include "dsp/pipeline/pipeline.hpp"
#include "dsp/session/measurement_session.hpp"

#include <array>
#include <cstdint>

namespace eical::daemon {

class HmiLink;

struct FrameLoopOptions {
  double fs_hz = dsp::kDefaultFs_hz;
  bool frame_triggers = true;      // the DAQ's own trigger channel is an input
  std::uint64_t live_every = 100;  // every n-th frame goes to the Live topic
};

class FrameLoop {
 public:
  static constexpr std::size_t kMaxChannels = 4;  // DDS, GPIO, CAN, spare

  FrameLoop(const FrameLoopOptions& options, drivers::StampedSource& source, dsp::MeasurementSession& session,
            dsp::Pipeline& live, FrameGuard& guard, RecordingHandoff& handoff, ServiceCounters& counters, HmiLink* hmi);

  // Before the first frame: an input whose triggers this loop decides on.
  void add_channel(TriggerChannel& channel);

  void on_frame(const dsp::Frame& in) noexcept;

  // After the source was reopened: its sample clock restarts, the DAQ clock continues.
  void continue_after_reopen() noexcept;
  // At the end of the data: a measurement the data ended inside is recorded with `cause`.
  void close_measurement(const dsp::Flag& cause);

  // The DAQ clock (sample index ↔ CLOCK_MONOTONIC) as the acquisition stamps say; any thread.
  [[nodiscard]] const drivers::SampleClock& daq_clock() const noexcept { return daq_clock_; }

 private:
  void continue_clock(dsp::Frame& f) noexcept;
  void filter_frame_trigger(dsp::Frame& f) const noexcept;
  // The acquisition stamp of the frame (CLOCK_MONOTONIC; 0 unknown), fed to the DAQ clock.
  std::int64_t observe_acquisition(const dsp::Frame& in) noexcept;
  void take_external_triggers(const dsp::Frame& f) noexcept;
  void track_measurement(bool nonfinite) noexcept;
  void step_live(const dsp::Frame& f) noexcept;
  void publish_live(const dsp::Frame& f, std::int64_t acquired_ns) noexcept;
  void hand_over_if_ready() noexcept;
  void publish_counters(const dsp::Frame& f) noexcept;

  FrameLoopOptions options_;
  drivers::StampedSource& source_;
  dsp::MeasurementSession& session_;
  dsp::Pipeline& live_;
  FrameGuard& guard_;
  RecordingHandoff& handoff_;
  ServiceCounters& counters_;
  HmiLink* hmi_;
  std::array<TriggerChannel*, kMaxChannels> channels_{};
  std::size_t n_channels_ = 0;
  TriggerGate gate_;
  drivers::SampleClock daq_clock_;
  std::int64_t stamp_seen_ = -1;  // last acquisition stamp observed (source's index)
  std::int64_t index_offset_ = 0, last_index_ = -1;
  bool gap_after_reopen_ = false;
  std::uint64_t frames_ = 0, started_seen_ = 0;
  RecordingNotes notes_;               // of the measurement running now
  double requested_p_ = std::nan("");  // P of the last M101 accepted from an external input
};

}  // namespace eical::daemon
