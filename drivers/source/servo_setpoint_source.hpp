#pragma once
// LinuxCNC's servo-rate commanded positions (the integration kit's halsampler stream) as
// the NC set-point next to a DAQ: the accelerations come from the sensor source, the
// set-point from the stream, combined on the DAQ clock.
//
// Two clocks, each mapped onto CLOCK_MONOTONIC by a minimum filter over arrival times
// (SampleClock): DAQ sample index (block arrivals on the acquisition thread) and servo
// cycle number (line arrivals on the feed thread). A frame's set-point is the commanded
// position at its sample time, interpolated linearly between servo cycles. Frames are held
// `hold_s` behind their sample time, so the servo lines covering them (≈10 ms late) and NC
// triggers sent over DDS by the M-codes (process start + DDS, up to ~0.75 s) are there
// before the frame leaves. A frame no servo cycle covers keeps the last set-point and is
// flagged cmd_missing (counted).
//
// Threads: the feed thread (reads the pipe; reopens it when LinuxCNC restarts, so eicald
// may start first) pushes cycles into an SPSC ring; read() runs on the acquisition thread:
// fixed queues, no allocation, lock or stream write.
#include "drivers/ring/fixed_queue.hpp"
#include "drivers/ring/spsc_ring.hpp"
#include "drivers/source/sample_clock.hpp"
#include "drivers/source/servo_stream_reader.hpp"
#include "drivers/source/source.hpp"

#include <array>
#include <atomic>
#include <memory>
#include <thread>

namespace eical::drivers {

struct ServoSetPointOptions {
  ServoStreamOptions stream;
  double hold_s = 1.0;    // frames leave this long after their sample time
  double reopen_s = 1.0;  // the pipe is reopened this often while it cannot be opened
};

// The two clocks' relation: what a recording writes as its set-point alignment.
struct ServoAlignment {
  bool known = false;
  double servo_cycle_at_sample0 = 0.0;  // fractional servo cycle number at DAQ sample 0
  double servo_rate_hz = 1000.0;
  double daq_delay_ms = 0.0;  // mean lateness of DAQ blocks behind their last sample
};

class ServoSetPointSource final : public Source {
 public:
  ServoSetPointSource(std::unique_ptr<Source> sensors, ServoSetPointOptions options);
  ~ServoSetPointSource() override;

  // Opens the sensor source (its absence is the error) and starts the feed thread, which
  // creates the pipe and waits for LinuxCNC without blocking start-up.
  void open() override;
  [[nodiscard]] const dsp::RunMeta& meta() const override { return sensors_->meta(); }
  std::size_t read(std::span<dsp::Frame> out) override;
  [[nodiscard]] bool at_end() const override { return sensors_->at_end() && held_.empty(); }
  [[nodiscard]] std::string_view name() const override { return name_; }
  [[nodiscard]] Backpressure backpressure() const override { return sensors_->backpressure(); }
  [[nodiscard]] std::int64_t sample_time_ns(std::int64_t sample_index) const override {
    return daq_clock_.time_ns(sample_index);
  }
  [[nodiscard]] SourceCounters counters() const override;
  void drain_diagnostics(const std::function<void(const std::string&)>& sink) override;

  // Any thread.
  [[nodiscard]] ServoAlignment alignment() const;

 private:
  struct ServoPoint {
    std::int64_t number;
    double cmd_mm[3];
    bool filled;
    bool restart;  // the stream restarted: forget the history before this point
  };
  enum class FeedEvent : int { connected, closed, malformed, cannot_open };
  struct FeedNote {
    FeedEvent event;
    std::int64_t cycle;
  };
  void stop_feed();
  void feed();
  void take_servo_points() noexcept;
  void set_point_of(dsp::Frame& f) noexcept;

  std::unique_ptr<Source> sensors_;
  ServoSetPointOptions options_;
  std::string name_;
  ServoStreamReader reader_;
  SampleClock daq_clock_;
  SpscRing<ServoPoint> points_{8192};
  SpscRing<FeedNote> notes_{64};
  FixedQueue<dsp::Frame> held_;
  FixedQueue<ServoPoint> history_{16384};
  std::array<dsp::Frame, 256> staging_{};
  double last_cmd_mm_[3] = {0.0, 0.0, 0.0};
  bool gap_pending_ = false;
  std::thread feed_thread_;
  std::atomic<bool> stop_{false};
  std::atomic<std::uint64_t> servo_points_{0}, setpoint_missing_{0}, dropped_{0};
  std::atomic<double> daq_delay_ms_{0.0};
};

}  // namespace eical::drivers
