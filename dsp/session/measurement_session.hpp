#pragma once
// One measurement from M101 to M103 as the DSP thread sees it: NC triggers (from the
// frame's trigger channel or queued from GPIO/CAN/DDS inputs, already mapped to the DAQ
// sample clock) drive the state machine, and the recorder keeps the frames. The same
// object runs in eicald and in `eical demo`, so the offline tools exercise the service's
// code path. Per-frame work does not allocate or throw.
#include "dsp/core/frame.hpp"
#include "dsp/core/sample_rate.hpp"
#include "dsp/session/measurement_recorder.hpp"
#include "dsp/session/measurement_state.hpp"

#include <array>
#include <cstdint>
#include <vector>

namespace eical::dsp {

struct SessionConfig {
  double fs_hz = kDefaultFs_hz;
  double max_measurement_s = 600.0;
  double pretrigger_s = 0.4;   // rest kept before M101 (bias window if M101 comes late)
  double posttrigger_s = 0.1;  // frames kept after M103
};

struct SessionCounters {
  std::uint64_t frames = 0;
  std::uint64_t frames_lost = 0;       // frames marked gap_before (the DAQ/driver lost some)
  std::uint64_t frames_flagged = 0;    // frames with any quality flag
  std::uint64_t triggers_refused = 0;  // triggers the state machine did not accept
  std::uint64_t triggers_late = 0;     // external triggers that arrived after their sample
  std::uint64_t trigger_queue_full = 0;
  std::uint64_t measurements_started = 0;
  std::uint64_t measurements_completed = 0;
};

class MeasurementSession {
 public:
  // sink: the recordings go there as they are recorded (MeasurementRecorder), none is held.
  explicit MeasurementSession(const SessionConfig& config, RecordingSink* sink = nullptr);

  // Per frame, DSP thread.
  void on_frame(const Frame& frame) noexcept;
  // An external trigger for `sample_index` on the DAQ clock; applied to that frame (or to
  // the next one if it already passed, counted as late). Returns false when the queue is full.
  bool queue_trigger(std::int64_t sample_index, int code) noexcept;
  // HMI commands that are not M-functions.
  Transition command(Event e, std::string_view reason = {});

  // A complete measurement is ready for evaluation (state EVALUATING, frames recorded).
  [[nodiscard]] bool measurement_ready() const noexcept { return recorder_.complete(); }
  // See MeasurementRecorder::take; then evaluate and call evaluation_done().
  bool take(std::vector<Frame>& spare) noexcept { return recorder_.take(spare); }
  // With a sink: see MeasurementRecorder::take_streamed; then evaluation_done().
  bool take_streamed() noexcept { return recorder_.take_streamed(); }
  void evaluation_done() { (void)state_.handle(Event::evaluation_done); }
  // The data ended inside a measurement (service stopped, source failed): the frames so
  // far become a complete recording, as if M103 had come now. False when none was running.
  bool close_now() noexcept;

  [[nodiscard]] const MeasurementState& state() const noexcept { return state_; }
  [[nodiscard]] const SessionCounters& counters() const noexcept { return counters_; }
  [[nodiscard]] std::uint64_t recorder_overflow() const noexcept { return recorder_.overflow_frames(); }
  [[nodiscard]] std::size_t recorder_capacity() const noexcept { return recorder_.capacity(); }

 private:
  void apply_trigger(int code) noexcept;

  struct Pending {
    std::int64_t sample_index;
    int code;
  };
  SessionConfig config_;
  MeasurementState state_;
  MeasurementRecorder recorder_;
  std::array<Pending, 16> pending_{};
  std::size_t pending_count_ = 0;
  SessionCounters counters_;
  std::size_t posttrigger_frames_;
};

}  // namespace eical::dsp
