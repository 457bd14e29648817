#pragma once
// A participant on one DDS domain with eical's six topics. Set-up errors throw
// BusError with Cyclone's reason; per-message calls return false and count, never throw.
// take_* wait on a waitset (no polling sleeps); wake() interrupts a waiting take from
// another thread (guard condition), for shutdown.
#include "drivers/dds/messages.hpp"

#include <atomic>
#include <chrono>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>

namespace eical::drivers::dds {

class BusError : public std::runtime_error {
 public:
  explicit BusError(const std::string& what) : std::runtime_error(what) {}
};

enum class Role { daemon, hmi };  // daemon: writes Status/Live/Result/Reply, reads Command

class Bus {
 public:
  Bus(int domain_id, Role role);
  ~Bus();
  Bus(const Bus&) = delete;
  Bus& operator=(const Bus&) = delete;

  bool publish(const StatusMsg& m);
  bool publish(const LiveMsg& m);
  bool publish(const ResultMsg& m);
  bool publish(const TraceMsg& m);
  bool publish(const ReplyMsg& m);
  bool send(const CommandMsg& m);

  // Each waits up to `timeout` for one sample of its topic.
  std::optional<StatusMsg> take_status(std::chrono::milliseconds timeout);
  std::optional<ResultMsg> take_result(std::chrono::milliseconds timeout);
  std::optional<TraceMsg> take_trace(std::chrono::milliseconds timeout);
  std::optional<CommandMsg> take_command(std::chrono::milliseconds timeout);
  std::optional<ReplyMsg> take_reply(std::chrono::milliseconds timeout);
  std::optional<LiveMsg> take_live(std::chrono::milliseconds timeout);

  void wake();  // interrupts take_* waiting in another thread
  // Any thread (the publisher, the evaluation and the command thread all write).
  [[nodiscard]] std::uint64_t write_errors() const { return write_errors_.load(std::memory_order_relaxed); }
  // Number of matched readers of the Result writer (a connected HMI).
  [[nodiscard]] int matched_result_readers() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::atomic<std::uint64_t> write_errors_{0};
};

}  // namespace eical::drivers::dds
