#pragma once
// Replays the frames of a recorded (or freshly simulated) run, either paced at fs like a
// real DAQ or free-running as fast as the consumer takes them.
#include "drivers/source/source.hpp"
#include "dsp/core/run.hpp"

#include <chrono>
#include <memory>

namespace eical::drivers {

enum class Pacing { realtime, free_running };

class ReplaySource final : public Source {
 public:
  ReplaySource(std::shared_ptr<const dsp::Run> run, Pacing pacing, std::string name = "replay");

  void open() override;
  [[nodiscard]] const dsp::RunMeta& meta() const override { return run_->meta; }
  std::size_t read(std::span<dsp::Frame> out) override;
  [[nodiscard]] bool at_end() const override { return next_ >= run_->frames.size(); }
  [[nodiscard]] std::string_view name() const override { return name_; }
  [[nodiscard]] Backpressure backpressure() const override {
    return pacing_ == Pacing::realtime ? Backpressure::drop_newest : Backpressure::wait;
  }

 private:
  std::shared_ptr<const dsp::Run> run_;
  Pacing pacing_;
  std::string name_;
  std::size_t next_ = 0;
  std::chrono::steady_clock::time_point start_{};
};

}  // namespace eical::drivers
