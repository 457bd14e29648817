#include "daemon/triggers/trigger_listener.hpp"

#include "daemon/system/log.hpp"

namespace eical::daemon {

TriggerListener::TriggerListener(std::unique_ptr<TriggerInput> input, TriggerChannel& channel)
    : input_(std::move(input)), channel_(channel), thread_([this] { loop(); }) {}

TriggerListener::~TriggerListener() {
  stop_.store(true);
  thread_.join();  // wait() returns within its 200 ms timeout
}

void TriggerListener::loop() {
  while (!stop_.load()) {
    auto r = input_->wait(200);
    log_verdicts();
    if (!r) continue;
    r->id = ++next_id_;
    codes_[r->id % 64] = r->code;
    received_.fetch_add(1, std::memory_order_relaxed);
    if (!channel_.send(*r))
      log(LogLevel::warning, "%s: M%d dropped: the trigger ring is full", input_->name().c_str(), r->code);
  }
}

void TriggerListener::log_verdicts() {
  TriggerVerdict v;
  while (channel_.take_verdict(v)) {
    const std::string what = describe(v, codes_[v.id % 64]);
    log(v.accepted ? LogLevel::info : LogLevel::warning, "%s: %s", input_->name().c_str(), what.c_str());
  }
}

}  // namespace eical::daemon
