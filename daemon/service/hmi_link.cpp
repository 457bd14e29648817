#include "daemon/service/hmi_link.hpp"

#include <algorithm>

#include "daemon/system/log.hpp"
#include "daemon/system/realtime.hpp"

#include <chrono>
#include <cstdlib>
#include <ctime>
#include <poll.h>
#include <stdexcept>
#include <sys/eventfd.h>
#include <unistd.h>

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
  status_.state = "STARTING";
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

void HmiLink::set_status(const drivers::dds::StatusMsg& s) {
  std::lock_guard lk(mu_);
  status_ = s;
}

void HmiLink::set_state(const std::string& state) {
  std::lock_guard lk(mu_);
  state_ = state;
}

void HmiLink::publish_result(const drivers::dds::ResultMsg& r) {
  if (!bus_->publish(r)) log(LogLevel::warning, "dds: result %s not published", r.program_id.c_str());
}

void HmiLink::publisher() {
  if (publisher_priority_ > 0) {
    const auto rt = make_this_thread_realtime(publisher_priority_, "eicald-pub");
    log(rt.ok ? LogLevel::info : LogLevel::warning, "%s", rt.message.c_str());
  }
  using clock = std::chrono::steady_clock;
  const auto status_period = std::chrono::duration_cast<clock::duration>(std::chrono::duration<double>(1.0 / config_.status_rate_hz));
  auto next_status = clock::now();
  while (!stop_.load()) {
    // Sleep until a Live sample arrives or the next Status is due.
    const auto wait_ms = std::chrono::ceil<std::chrono::milliseconds>(next_status - clock::now()).count();
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
      for (int i = 0; i < 3; ++i) m.pos_mm[static_cast<std::size_t>(i)] = latest.pos_mm[i], m.vel_mm_s[static_cast<std::size_t>(i)] = latest.vel_mm_s[i];
      m.integrating = latest.integrating;
      m.acquired_ns = latest.acquired_ns;
      (void)bus_->publish(m);
    }
    if (clock::now() >= next_status) {
      drivers::dds::StatusMsg st;
      {
        std::lock_guard lk(mu_);
        st = status_;
      }
      st.daemon = name_;
      st.time_ns = now_ns();
      (void)bus_->publish(st);
      next_status += status_period;
      if (next_status < clock::now()) next_status = clock::now() + status_period;  // after a stall: no burst
    }
  }
}

void HmiLink::commander() {
  while (!stop_.load()) {
    const auto cmd = bus_->take_command(std::chrono::milliseconds(500));
    if (!cmd) continue;
    ++commands_;
    drivers::dds::ReplyMsg reply;
    reply.sender = cmd->sender;
    reply.request_id = cmd->request_id;
    // `eical trigger` resends until it sees a Reply: a resend of an accepted trigger is
    // answered again but not queued twice (a doubled M102 would add a segment).
    const std::pair<std::string, std::uint32_t> key{cmd->sender, cmd->request_id};
    const bool resend = std::find(recent_triggers_.begin(), recent_triggers_.end(), key) != recent_triggers_.end();
    if (cmd->action == "trigger" && resend) {
      reply.ok = true;
      reply.message = "M" + std::to_string(cmd->code) + " already queued (resend ignored)";
    } else if (cmd->action == "trigger" && (cmd->code == 101 || cmd->code == 102 || cmd->code == 103)) {
      reply.ok = triggers_.try_push({cmd->time_ns, cmd->code});
      if (reply.ok) {
        recent_triggers_.push_back(key);
        if (recent_triggers_.size() > 64) recent_triggers_.pop_front();
      }
      reply.message = reply.ok ? "M" + std::to_string(cmd->code) + " queued for the DAQ clock" : "trigger queue full";
    } else {
      reply.ok = false;
      reply.message = "unknown command '" + cmd->action + "' (code " + std::to_string(cmd->code) + "); use trigger 101|102|103";
    }
    {
      std::lock_guard lk(mu_);
      reply.state = state_;
    }
    (void)bus_->publish(reply);
    log(LogLevel::info, "command from %s: %s %d -> %s", cmd->sender.c_str(), cmd->action.c_str(), cmd->code, reply.message.c_str());
  }
}

}  // namespace eical::daemon
