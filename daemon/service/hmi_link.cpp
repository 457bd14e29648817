#include "daemon/service/hmi_link.hpp"

#include <algorithm>

#include "daemon/system/log.hpp"
#include "daemon/system/realtime.hpp"

#include <poll.h>
#include <sys/eventfd.h>
#include <unistd.h>
#include <chrono>
#include <cstdlib>
#include <ctime>
#include <stdexcept>

namespace eical::daemon {
namespace {

std::int64_t now_ns() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1000000000 + ts.tv_nsec;
}

}  // namespace

HmiLink::HmiLink(const DdsConfig& config, std::string daemon_name, int publisher_priority)
    : config_(config), name_(std::move(daemon_name)), publisher_priority_(publisher_priority) {
  drivers::dds::StatusMsg starting;
  starting.state = "STARTING";
  status_.fill(starting);
  if (!config_.config_uri.empty()) ::setenv("CYCLONEDDS_URI", config_.config_uri.c_str(), 1);
  bus_ = std::make_unique<drivers::dds::Bus>(config_.domain_id, drivers::dds::Role::daemon);
  wake_fd_ = ::eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC);
  if (wake_fd_ < 0) throw std::runtime_error("hmi: eventfd failed");
  publisher_ = std::thread([this] { publisher(); });
  commander_ = std::thread([this] { commander(); });
}

HmiLink::~HmiLink() {
  stop_.store(true);
  bus_->wake();
  const std::uint64_t one = 1;
  (void)!::write(wake_fd_, &one, sizeof one);
  commander_.join();
  publisher_.join();
  ::close(wake_fd_);
}

void HmiLink::push_live(const LiveSample& s) noexcept {
  if (!live_.push_or_drop(s)) return;
  const std::uint64_t one = 1;
  (void)!::write(wake_fd_, &one, sizeof one);  // non-blocking; a full counter is still a wake-up
}

void HmiLink::publish_trace(const drivers::dds::TraceMsg& t) {
  if (!bus_->publish(t)) log(LogLevel::warning, "dds: trace %s not published", t.program_id.c_str());
}

void HmiLink::set_status(const drivers::dds::StatusMsg& s, dsp::State state) {
  status_.back() = s;
  status_.publish();
  state_.store(static_cast<int>(state), std::memory_order_relaxed);
}

void HmiLink::publish_result(const drivers::dds::ResultMsg& r) {
  if (!bus_->publish(r)) log(LogLevel::warning, "dds: result %s not published", r.program_id.c_str());
}

void HmiLink::publisher() {
  if (publisher_priority_ > 0) {
    const auto rt = make_this_thread_realtime(publisher_priority_, "eicald-pub");
    log(rt.ok ? LogLevel::info : LogLevel::warning, "%s", rt.message.c_str());
  }
  using Clock = std::chrono::steady_clock;
  const auto status_period =
      std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(1.0 / config_.status_rate_hz));
  auto next_status = Clock::now();
  while (!stop_.load()) {
    // Sleep until a Live sample arrives or the next Status is due.
    const auto wait_ms = std::chrono::ceil<std::chrono::milliseconds>(next_status - Clock::now()).count();
    pollfd p{wake_fd_, POLLIN, 0};
    if (wait_ms > 0 && ::poll(&p, 1, static_cast<int>(wait_ms)) > 0) {
      std::uint64_t n = 0;
      (void)!::read(wake_fd_, &n, sizeof n);
    }
    if (stop_.load()) break;
    // Live: the newest sample handed over since the last wake-up.
    LiveSample s{}, latest{};
    bool any = false;
    while (live_.try_pop(s)) latest = s, any = true;
    if (any) {
      drivers::dds::LiveMsg m;
      m.daemon = name_;
      m.sample_index = latest.sample_index;
      for (int i = 0; i < 3; ++i)
        m.pos_mm[static_cast<std::size_t>(i)] = latest.pos_mm[i],
        m.vel_mm_s[static_cast<std::size_t>(i)] = latest.vel_mm_s[i];
      m.integrating = latest.integrating;
      m.acquired_ns = latest.acquired_ns;
      (void)bus_->publish(m);
    }
    if (Clock::now() >= next_status) {
      // The newest Status the status thread handed over (its strings are the front
      // buffer's: nothing is copied here).
      (void)status_.update();
      drivers::dds::StatusMsg& st = status_.front();
      st.daemon = name_;
      st.time_ns = now_ns();
      (void)bus_->publish(st);
      next_status += status_period;
      if (next_status < Clock::now()) next_status = Clock::now() + status_period;  // after a stall: no burst
    }
  }
}

drivers::dds::ReplyMsg HmiLink::answer_trigger(const drivers::dds::CommandMsg& cmd) {
  drivers::dds::ReplyMsg reply;
  TriggerRequest r;
  r.id = ++next_trigger_id_;
  r.time_ns = cmd.time_ns;
  r.code = cmd.code;
  r.p = cmd.p;
  if (!triggers_.send(r)) {
    reply.ok = false;
    reply.message = "M" + std::to_string(cmd.code) + " refused: the trigger queue is full";
    return reply;
  }
  // The DSP thread decides at its next frame (it knows the measurement state and the
  // triggers already queued). Verdicts of earlier, unanswered requests are skipped.
  const auto end = std::chrono::steady_clock::now() + std::chrono::milliseconds(500);
  for (;;) {
    TriggerVerdict v;
    while (triggers_.take_verdict(v)) {
      if (v.id != r.id) continue;
      reply.ok = v.accepted;
      reply.message = describe(v, cmd.code);
      reply.state = std::string(dsp::to_string(v.state));
      return reply;
    }
    const auto left =
        std::chrono::duration_cast<std::chrono::milliseconds>(end - std::chrono::steady_clock::now()).count();
    if (left <= 0) break;
    triggers_.wait_verdict(static_cast<int>(left));
  }
  reply.ok = true;
  reply.message =
      "M" + std::to_string(cmd.code) + " queued for the DAQ clock (not confirmed yet: no frames handled for 0.5 s)";
  return reply;
}

drivers::dds::ReplyMsg HmiLink::answer(const drivers::dds::CommandMsg& cmd) {
  drivers::dds::ReplyMsg reply;
  const auto state_now = [&] { return std::string(dsp::to_string(static_cast<dsp::State>(state_.load()))); };
  if (cmd.sender.size() > kMaxSenderBytes || cmd.action.size() > kMaxActionBytes) {
    reply.ok = false;
    reply.message = "command refused: sender (" + std::to_string(cmd.sender.size()) + " bytes) or action (" +
                    std::to_string(cmd.action.size()) + " bytes) longer than " + std::to_string(kMaxSenderBytes) +
                    " / " + std::to_string(kMaxActionBytes);
    reply.state = state_now();
    return reply;
  }
  const auto seen = std::find_if(answered_.begin(), answered_.end(), [&](const Answered& a) {
    return a.sender == cmd.sender && a.request_id == cmd.request_id;
  });
  if (cmd.action == "trigger" && seen != answered_.end())
    return seen->reply;  // `eical trigger` resends until it sees a Reply
  if (cmd.action == "trigger" && is_nc_trigger(cmd.code)) {
    reply = answer_trigger(cmd);
    if (reply.state.empty()) reply.state = state_now();
    answered_.push_back({cmd.sender, cmd.request_id, reply});
    if (answered_.size() > 64) answered_.pop_front();
    return reply;
  }
  reply.ok = false;
  reply.message = "unknown command '" + cmd.action + "' (code " + std::to_string(cmd.code) + "); use trigger " +
                  std::to_string(kProgramStart) + "|" + std::to_string(kSegmentMark) + "|" +
                  std::to_string(kProgramEnd);
  reply.state = state_now();
  return reply;
}

void HmiLink::log_answer(const drivers::dds::CommandMsg& cmd, const drivers::dds::ReplyMsg& reply) {
  const std::string sender = cmd.sender.substr(0, kMaxSenderBytes), action = cmd.action.substr(0, kMaxActionBytes);
  if (reply.ok) {
    log(LogLevel::info, "command from %s: %s %d -> %s", sender.c_str(), action.c_str(), cmd.code,
        reply.message.c_str());
    return;
  }
  const auto now = std::chrono::steady_clock::now();
  if (now - log_window_start_ > std::chrono::duration<double>(kLogWindowS)) {
    if (refusals_unlogged_ > 0)
      log(LogLevel::warning, "%llu more commands refused in %.0f s (not logged one by one)",
          static_cast<unsigned long long>(refusals_unlogged_), kLogWindowS);
    log_window_start_ = now, refusals_logged_ = 0, refusals_unlogged_ = 0;
  }
  if (refusals_logged_ < kRefusalsLogged) {
    ++refusals_logged_;
    log(LogLevel::warning, "command from %s: %s %d -> %s", sender.c_str(), action.c_str(), cmd.code,
        reply.message.c_str());
  } else {
    ++refusals_unlogged_;
  }
}

void HmiLink::commander() {
  while (!stop_.load()) {
    const auto cmd = bus_->take_command(std::chrono::milliseconds(500));
    if (!cmd) continue;
    ++commands_;
    drivers::dds::ReplyMsg reply = answer(*cmd);
    reply.sender = cmd->sender.substr(0, kMaxSenderBytes);
    reply.request_id = cmd->request_id;
    (void)bus_->publish(reply);
    log_answer(*cmd, reply);
  }
}

}  // namespace eical::daemon
