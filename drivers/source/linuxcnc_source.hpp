#pragma once
// LinuxCNC as the NC of the simulated machine: the servo-rate joint positions LinuxCNC
// streams through the integration kit (integrations/linuxcnc: HAL sampler → eical-halsampler
// → a named pipe) drive eical's machine, sensor and DAQ simulation (WindowedSim), so the
// accelerations come from LinuxCNC's trajectory planner.
//
// Threads: a worker thread of this source (in the role of the DAQ card's processor) reads
// the pipe (ServoStreamReader: poll(), no polling sleeps), keeps the servo clock, and
// simulates a block every block_cycles; the simulation allocates (sim::simulate is a batch
// computation: it is the simulated DAQ, not eicald's acquisition path), the frames wait in
// a fixed queue and nothing on the worker writes a stream: M-code markers and the stream
// summary are handed over through drain_diagnostics() and the destructor. eicald's
// acquisition thread only pops finished frames from an SPSC ring in read():
// allocation-free, waiting on a semaphore with a 100 ms bound so the pump still sees its
// stop flag.
// Latency of a frame behind its servo cycle: hold_s (default 1 s), which must exceed both
// the simulation latency (block + lookahead cycles, the block's simulation time,
// halsampler's ~10 ms wake-up) and the time an M-code's `eical trigger` needs to reach
// eicald (process start and DDS discovery: up to ~0.75 s measured on 2 loaded cores). sample_time_ns() gives the
// servo cycle's own CLOCK_MONOTONIC time (ServoClock), so eicald maps trigger times onto
// the right frame whatever that latency.
#include "drivers/ring/fixed_queue.hpp"
#include "drivers/ring/spsc_ring.hpp"
#include "drivers/source/linuxcnc_options.hpp"
#include "drivers/source/sample_clock.hpp"
#include "drivers/source/servo_stream_reader.hpp"
#include "drivers/source/source.hpp"
#include "drivers/source/windowed_sim.hpp"

#include <atomic>
#include <condition_variable>
#include <filesystem>
#include <memory>
#include <mutex>
#include <semaphore>
#include <string>
#include <thread>

namespace eical::drivers {

// What the worker learned about the stream (for the log and tests).
struct LinuxcncStreamStats {
  std::uint64_t lines = 0, lost_cycles = 0, overrun_lines = 0, dropped_frames = 0, blocks = 0;
  std::int64_t first_number = -1;
  std::int64_t clock_offset_ns = 0;                // CLOCK_MONOTONIC of servo cycle 0 (SampleClock)
  double mean_delay_ms = 0.0, max_delay_ms = 0.0;  // lines behind their cycle
  double max_block_sim_ms = 0.0;                   // longest simulation of one block
  double max_following_error_mm = 0.0;             // |cmd − fb| largest seen
};

class LinuxcncSource final : public Source {
 public:
  LinuxcncSource(sim::Scenario scenario, LinuxcncSourceOptions options);
  ~LinuxcncSource() override;

  // Creates the named pipe if absent (mode 0666: LinuxCNC may run as another user), opens
  // it and waits for the first servo line; SourceError naming the cause otherwise.
  void open() override;
  [[nodiscard]] const dsp::RunMeta& meta() const override { return scenario_.meta; }
  std::size_t read(std::span<dsp::Frame> out) override;
  [[nodiscard]] bool at_end() const override { return false; }
  [[nodiscard]] std::string_view name() const override { return "linuxcnc"; }
  [[nodiscard]] Backpressure backpressure() const override { return Backpressure::drop_newest; }
  [[nodiscard]] std::int64_t sample_time_ns(std::int64_t sample_index) const override;

  [[nodiscard]] LinuxcncStreamStats stats() const;
  [[nodiscard]] SourceCounters counters() const override;
  void drain_diagnostics(const std::function<void(const std::string&)>& sink) override;

 private:
  // An M-code marker seen in the stream (EICAL_MARK=1 in the kit), logged off the worker.
  struct MarkerEvent {
    std::uint32_t marker;
    std::int64_t cycle, sample;
  };
  // The worker's statistics, readable from any thread.
  struct SharedStats {
    std::atomic<std::uint64_t> lines{0}, lost_cycles{0}, overrun_lines{0}, dropped_frames{0}, blocks{0};
    std::atomic<std::int64_t> first_number{-1}, clock_offset_ns{0};
    std::atomic<double> mean_delay_ms{0.0}, max_delay_ms{0.0}, max_block_sim_ms{0.0}, max_following_error_mm{0.0};
  };
  class Worker;  // work()'s loop and its stages (linuxcnc_source.cpp)
  void stop_worker();
  void work();
  void fail(const std::string& why);
  void publish(const ServoStreamReader& reader, const LinuxcncStreamStats& local);
  [[nodiscard]] std::string summary() const;

  sim::Scenario scenario_;
  LinuxcncSourceOptions options_;
  std::unique_ptr<SpscRing<dsp::Frame>> ring_;
  std::unique_ptr<FixedQueue<dsp::Frame>> held_;  // worker: frames waiting out hold_s
  std::unique_ptr<SpscRing<MarkerEvent>> markers_;
  std::counting_semaphore<> available_{0};
  std::thread worker_;
  std::unique_ptr<ServoStreamReader> reader_;
  std::atomic<bool> failed_{false};
  std::atomic<std::int64_t> first_number_{-1};
  int ratio_ = 10;         // frames per servo cycle
  mutable std::mutex mu_;  // error_ and the first line (failure and start only, never per sample)
  std::condition_variable cv_;
  bool first_line_ = false;
  bool ran_ = false;  // a worker ran since the last summary
  std::string error_;
  SharedStats shared_;
};

}  // namespace eical::drivers
