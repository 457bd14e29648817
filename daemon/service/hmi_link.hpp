#pragma once
// eicald's side of the HMI bus: a publisher thread (Status at status_rate_hz, Live
// samples handed over by the DSP thread through an SPSC ring, Results and Traces as they
// are written) and a command thread (Command topic → NC triggers for the DSP thread, whose
// verdict it answers with a Reply: a refused M101 says why). The DSP thread only touches
// rings and eventfds (the Live wake-up of the publisher, the verdict wake-up of the
// command thread): no lock, allocation or DDS call on the DSP thread; the publisher sleeps
// on the eventfd, not on a timer, so Live latency is not a tick.
#include "daemon/config/daemon_config.hpp"
#include "daemon/triggers/trigger_channel.hpp"
#include "drivers/dds/bus.hpp"
#include "drivers/ring/spsc_ring.hpp"
#include "drivers/ring/triple_buffer.hpp"
#include "dsp/session/measurement_state.hpp"

#include <atomic>
#include <chrono>
#include <deque>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

namespace eical::daemon {

struct LiveSample {
  std::int64_t sample_index;
  double pos_mm[3], vel_mm_s[3];
  bool integrating;
  std::int64_t acquired_ns;  // CLOCK_MONOTONIC when the acquisition thread had the sample
};

class HmiLink {
 public:
  // Throws dds::BusError when the bus cannot start (bad CYCLONEDDS_URI, no network).
  // publisher_priority: SCHED_FIFO of the Live/Status publisher (0 = normal), below the
  // DSP thread's so that it never delays the sample path but is not queued behind
  // ordinary work on a loaded control PC.
  HmiLink(const DdsConfig& config, std::string daemon_name, int publisher_priority = 0);
  ~HmiLink();

  // DSP thread.
  void push_live(const LiveSample& s) noexcept;
  // The NC triggers of the Command topic, for the DSP thread's FrameLoop.
  [[nodiscard]] TriggerChannel& triggers() noexcept { return triggers_; }

  // The status thread: the next Status and the state command replies name. Lock-free (a
  // triple buffer): the real-time publisher never waits for the status thread.
  void set_status(const drivers::dds::StatusMsg& s, dsp::State state);
  // Any thread (the evaluation thread).
  void publish_result(const drivers::dds::ResultMsg& r);
  void publish_trace(const drivers::dds::TraceMsg& t);

  [[nodiscard]] std::uint64_t commands_received() const { return commands_.load(); }

  // A Command's sender and action are short names; longer ones are refused before they are
  // logged, remembered or echoed (a 1 MB sender would otherwise be kept for every answer).
  static constexpr std::size_t kMaxSenderBytes = 64, kMaxActionBytes = 32;
  // Refused commands are logged up to this many per kLogWindowS, then counted in one line
  // (an HMI flooding at 1 kHz would otherwise write 1000 journal lines a second).
  static constexpr int kRefusalsLogged = 5;
  static constexpr double kLogWindowS = 10.0;
  [[nodiscard]] std::uint64_t live_overruns() const { return live_.overruns(); }
  [[nodiscard]] std::uint64_t write_errors() const { return bus_->write_errors(); }

 private:
  void publisher();
  void commander();
  drivers::dds::ReplyMsg answer_trigger(const drivers::dds::CommandMsg& cmd);
  drivers::dds::ReplyMsg answer(const drivers::dds::CommandMsg& cmd);
  void log_answer(const drivers::dds::CommandMsg& cmd, const drivers::dds::ReplyMsg& reply);

  DdsConfig config_;
  std::string name_;
  std::unique_ptr<drivers::dds::Bus> bus_;
  drivers::SpscRing<LiveSample> live_{1024};
  TriggerChannel triggers_{"dds"};
  std::uint32_t next_trigger_id_ = 0;                           // command thread
  drivers::TripleBuffer<drivers::dds::StatusMsg> status_;       // status thread → publisher
  std::atomic<int> state_{static_cast<int>(dsp::State::idle)};  // for the command thread's replies
  std::atomic<bool> stop_{false};
  std::atomic<std::uint64_t> commands_{0};
  int publisher_priority_ = 0;
  int wake_fd_ = -1;  // eventfd: DSP thread → publisher
  std::thread publisher_, commander_;
  // Command thread: the replies to the last triggers, by (sender, request id): a resend is
  // answered the same and never queued twice (a doubled M102 would add a segment).
  struct Answered {
    std::string sender;
    std::uint32_t request_id;
    drivers::dds::ReplyMsg reply;
  };
  std::deque<Answered> answered_;
  // Command thread: refusals logged in the current window, and those only counted.
  std::chrono::steady_clock::time_point log_window_start_{};
  int refusals_logged_ = 0;
  std::uint64_t refusals_unlogged_ = 0;
};

}  // namespace eical::daemon
