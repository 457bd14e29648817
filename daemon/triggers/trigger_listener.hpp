#pragma once
// One thread per hardware trigger input: waits for its events (kernel-timestamped GPIO
// edges, CAN frames), hands each to the DSP thread through the input's TriggerChannel and
// logs the DSP thread's verdict (a refused M101 names why). Not real-time: it may log.
#include "daemon/triggers/trigger_channel.hpp"
#include "daemon/triggers/trigger_input.hpp"

#include <atomic>
#include <memory>
#include <thread>
#include <vector>

namespace eical::daemon {

class TriggerListener {
 public:
  TriggerListener(std::unique_ptr<TriggerInput> input, TriggerChannel& channel);
  ~TriggerListener();
  TriggerListener(const TriggerListener&) = delete;
  TriggerListener& operator=(const TriggerListener&) = delete;

  [[nodiscard]] std::uint64_t received() const noexcept { return received_.load(std::memory_order_relaxed); }
  [[nodiscard]] std::uint64_t ignored() const noexcept { return input_->ignored(); }
  [[nodiscard]] const TriggerChannel& channel() const noexcept { return channel_; }

 private:
  void loop();
  void log_verdicts();

  std::unique_ptr<TriggerInput> input_;
  TriggerChannel& channel_;
  std::atomic<bool> stop_{false};
  std::atomic<std::uint64_t> received_{0};
  std::uint32_t next_id_ = 0;
  int codes_[64] = {};  // code of request id % 64, for the log
  std::thread thread_;
};

}  // namespace eical::daemon
