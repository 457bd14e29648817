#pragma once
// The default backend when no hardware is present: a simulated machine and its sensors
// (sim::simulate) delivered like a DAQ — paced at fs or free-running. The NC program's
// M101/M102/M103 arrive on the frames' trigger channel, as from a PLC output wired to
// the DAQ's trigger input. With `repeat` the program runs again after `idle_s` of rest
// (the return to the start position is not simulated: the set-point jumps back while no
// measurement is running).
#include "drivers/source/replay_source.hpp"
#include "sim/scenario.hpp"

#include <memory>

namespace eical::drivers {

struct SimSourceOptions {
  Pacing pacing = Pacing::realtime;
  bool repeat = false;
  double idle_s = 2.0;
  // Also keep the simulator's true relative position of every frame of the program pass
  // (true_rel_mm()): what the demo and tests compare a measurement with. Off in the daemon.
  bool keep_truth = false;
};

class SimSource final : public Source {
 public:
  SimSource(sim::Scenario scenario, SimSourceOptions options);

  void open() override;
  [[nodiscard]] const dsp::RunMeta& meta() const override { return run_->meta; }
  std::size_t read(std::span<dsp::Frame> out) override;
  [[nodiscard]] bool at_end() const override;
  [[nodiscard]] std::string_view name() const override { return "sim"; }
  // Paced in real time, its sample clock is ideal: sample k is taken at the first read's
  // time + k / fs, whenever a loaded machine lets read() return it. Stamping the return
  // time instead made late blocks look early on the DAQ clock, so an M103 sent for its
  // sample landed before the final rest (CLOCK_MONOTONIC ns; 0 unpaced: not known).
  [[nodiscard]] std::int64_t sample_time_ns(std::int64_t sample_index) const override;
  [[nodiscard]] Backpressure backpressure() const override {
    return options_.pacing == Pacing::realtime ? Backpressure::drop_newest : Backpressure::wait;
  }
  // The simulated run of one program pass (with its truth.toml).
  [[nodiscard]] const std::shared_ptr<const dsp::Run>& program_run() const { return run_; }
  // The true relative position (mm) at each frame of program_run(); empty without keep_truth.
  [[nodiscard]] const std::vector<Eigen::Vector3d>& true_rel_mm() const { return truth_; }

 private:
  sim::Scenario scenario_;
  SimSourceOptions options_;
  std::shared_ptr<const dsp::Run> run_;
  std::vector<Eigen::Vector3d> truth_;
  std::size_t pos_ = 0;          // position within program + idle cycle
  std::size_t idle_frames_ = 0;  // idle frames after each program pass
  std::size_t rest_frames_ = 0;  // rest frames at the program's start, cycled while idle
  std::int64_t next_index_ = 0;  // sample index of the next frame
  bool finished_ = false;
  std::chrono::steady_clock::time_point start_{};
};

}  // namespace eical::drivers
