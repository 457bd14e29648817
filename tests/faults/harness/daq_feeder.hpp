#pragma once
// A DAQ on eicald's [source] kind = "daq_stream" pipe: frames encoded in the USB DAQ's wire
// protocol (FrameEncoder), written in phases, each at its own pace (1 = real time at
// fs_hz, 3 = three times faster) or a silence (the DAQ stalls: nothing written, the pipe
// kept open). When eicald reopens the pipe after a failure the writer sees EPIPE and opens
// it again, as a DAQ bridge that reconnects would.
#include "dsp/core/frame.hpp"

#include <atomic>
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <thread>
#include <vector>

namespace eical::faults {

struct FeedPhase {
  std::vector<dsp::Frame> frames;  // empty: a silence of silence_s
  double pace = 1.0;               // samples per second / fs_hz
  double silence_s = 0.0;
};

// A circle of the simulator (R 10 mm, F2500, two repeats) as a DAQ sends it: accelerations
// and temperatures, its M-codes on the trigger channel, no set-point; `rest_s` of rest before.
std::vector<dsp::Frame> daq_circle(double rest_s);
// Rest (the machine still) for `seconds`.
std::vector<dsp::Frame> daq_rest(double seconds);

class DaqFeeder {
 public:
  DaqFeeder(std::filesystem::path fifo, std::vector<FeedPhase> phases, double fs_hz = 10000.0);
  ~DaqFeeder();  // stops writing
  DaqFeeder(const DaqFeeder&) = delete;
  DaqFeeder& operator=(const DaqFeeder&) = delete;

  // Index of the phase being written (phases.size() when done); when it began.
  [[nodiscard]] std::size_t phase() const { return phase_.load(); }
  [[nodiscard]] std::chrono::steady_clock::time_point phase_started(std::size_t k) const;
  [[nodiscard]] bool done() const { return phase() >= phases_.size(); }

 private:
  void run();
  bool write_all(int& fd, const std::vector<std::uint8_t>& bytes);

  std::filesystem::path fifo_;
  std::vector<FeedPhase> phases_;
  double fs_hz_;
  std::vector<std::atomic<std::int64_t>> started_ns_;
  std::atomic<std::size_t> phase_{0};
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace eical::faults
