#include "drivers/source/servo_setpoint_source.hpp"

#include "drivers/source/stamped_source.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>

namespace eical::drivers {
namespace {

std::size_t held_capacity(const Source& sensors, double hold_s) {
  return static_cast<std::size_t>(std::ceil(hold_s * sensors.meta().acquisition.fs_hz)) + 8192;
}

}  // namespace

ServoSetPointSource::ServoSetPointSource(std::unique_ptr<Source> sensors, ServoSetPointOptions options)
    : sensors_(std::move(sensors)),
      options_(std::move(options)),
      name_(std::string(sensors_->name()) + "+servo"),
      reader_(options_.stream),
      // 2 s windows of samples for the DAQ's minimum filter (as the servo clock's 2000 cycles).
      daq_clock_(1.0 / sensors_->meta().acquisition.fs_hz,
                 static_cast<std::int64_t>(2.0 * sensors_->meta().acquisition.fs_hz)),
      held_(held_capacity(*sensors_, options_.hold_s)) {}

ServoSetPointSource::~ServoSetPointSource() { stop_feed(); }

void ServoSetPointSource::stop_feed() {
  if (!feed_thread_.joinable()) return;
  stop_.store(true);
  reader_.wake();
  feed_thread_.join();
}

void ServoSetPointSource::open() {
  stop_feed();
  sensors_->open();
  held_.clear();
  history_.clear();
  daq_clock_.reset();
  ServoPoint p{};
  while (points_.try_pop(p)) {
  }
  gap_pending_ = false;
  stop_.store(false);
  feed_thread_ = std::thread([this] { feed(); });
}

void ServoSetPointSource::feed() {
  using S = ServoStreamReader::Status;
  bool restart = true;
  while (!stop_.load()) {
    try {
      reader_.open();
    } catch (const SourceError&) {
      (void)notes_.push_or_drop({FeedEvent::cannot_open, 0});
      std::this_thread::sleep_for(std::chrono::duration<double>(options_.reopen_s));  // a retry timer, not a data poll
      continue;
    }
    bool connected = false;
    for (;;) {
      const S s = reader_.read(500, [&](const ServoCycle& c) {
        if (!connected) connected = true, (void)notes_.push_or_drop({FeedEvent::connected, c.number});
        ServoPoint p{c.number, {c.cmd_mm[0], c.cmd_mm[1], c.cmd_mm[2]}, c.filled, restart};
        restart = false;
        (void)points_.push_or_drop(p);  // a full ring is counted by the ring
        servo_points_.fetch_add(1, std::memory_order_relaxed);
      });
      if (s == S::data || s == S::timeout) continue;
      if (s == S::woken) return;
      // The writer went away or the stream broke: a new stream starts with new numbers.
      (void)notes_.push_or_drop(
          {s == S::closed ? FeedEvent::closed : FeedEvent::malformed, reader_.stats().last_number});
      restart = true;
      if (s == S::error) {
        reader_.restart();  // keep the pipe: closing it would break LinuxCNC's writer
        continue;
      }
      break;
    }
  }
}

void ServoSetPointSource::take_servo_points() noexcept {
  ServoPoint p{};
  while (points_.try_pop(p)) {
    if (p.restart) history_.clear();
    if (history_.full()) history_.pop();
    (void)history_.push(p);
  }
}

void ServoSetPointSource::set_point_of(dsp::Frame& f) noexcept {
  const double c = reader_.clock().number_at(daq_clock_.time_ns(f.sample_index));
  bool found = false, filled = false;
  if (!history_.empty() && std::isfinite(c)) {
    const double k = c - static_cast<double>(history_.front().number);  // cycles are consecutive (lost ones filled)
    const auto k0 = static_cast<std::int64_t>(std::floor(k));
    if (k0 >= 0 && k0 + 1 < static_cast<std::int64_t>(history_.size())) {
      const ServoPoint& a = history_.at(static_cast<std::size_t>(k0));
      const ServoPoint& b = history_.at(static_cast<std::size_t>(k0 + 1));
      const double u = k - static_cast<double>(k0);
      for (int i = 0; i < 3; ++i) last_cmd_mm_[i] = a.cmd_mm[i] + (b.cmd_mm[i] - a.cmd_mm[i]) * u;
      found = b.number == a.number + 1;
      filled = a.filled || b.filled;
    }
  }
  for (int i = 0; i < 3; ++i) f.cmd_mm[i] = last_cmd_mm_[i];
  if (found && !filled) {
    f.flags &= ~dsp::frame_flag::cmd_missing;
  } else {
    f.flags |= dsp::frame_flag::cmd_missing;
    setpoint_missing_.fetch_add(1, std::memory_order_relaxed);
  }
}

std::size_t ServoSetPointSource::read(std::span<dsp::Frame> out) {
  const std::size_t n = sensors_->read(staging_);
  if (n > 0) {
    daq_clock_.observe(staging_[n - 1].sample_index, monotonic_ns());
    daq_delay_ms_.store(daq_clock_.mean_delay_ms(), std::memory_order_relaxed);
    for (std::size_t k = 0; k < n; ++k) {
      dsp::Frame f = staging_[k];
      if (gap_pending_) f.flags |= dsp::frame_flag::gap_before, gap_pending_ = false;
      if (!held_.push(f)) gap_pending_ = true, dropped_.fetch_add(1, std::memory_order_relaxed);
    }
  }
  take_servo_points();
  const std::int64_t now = monotonic_ns();
  const auto hold_ns = static_cast<std::int64_t>(options_.hold_s * 1e9);
  std::size_t released = 0;
  while (released < out.size() && !held_.empty() && daq_clock_.time_ns(held_.front().sample_index) + hold_ns <= now) {
    dsp::Frame f = held_.front();
    held_.pop();
    set_point_of(f);
    out[released++] = f;
  }
  // History older than the oldest frame still waiting is no longer needed.
  const double oldest = held_.empty() ? reader_.clock().number_at(now - hold_ns)
                                      : reader_.clock().number_at(daq_clock_.time_ns(held_.front().sample_index));
  while (std::isfinite(oldest) && history_.size() > 2 && static_cast<double>(history_.at(1).number) < oldest - 2.0)
    history_.pop();
  return released;
}

SourceCounters ServoSetPointSource::counters() const {
  SourceCounters c = sensors_->counters();
  c.dropped_frames += dropped_.load(std::memory_order_relaxed) + points_.overruns();
  c.setpoint_samples = servo_points_.load(std::memory_order_relaxed);
  c.setpoint_missing = setpoint_missing_.load(std::memory_order_relaxed);
  return c;
}

void ServoSetPointSource::drain_diagnostics(const std::function<void(const std::string&)>& sink) {
  sensors_->drain_diagnostics(sink);
  FeedNote n{};
  while (notes_.try_pop(n)) {
    const std::string pipe = options_.stream.fifo.string();
    switch (n.event) {
      case FeedEvent::connected:
        sink("setpoint: servo stream on " + pipe + " connected at cycle " + std::to_string(n.cycle));
        break;
      case FeedEvent::closed:
        sink("setpoint: servo stream on " + pipe + " closed after cycle " + std::to_string(n.cycle) +
             "; waiting for LinuxCNC");
        break;
      case FeedEvent::malformed:
        sink("setpoint: servo stream on " + pipe + " broken after cycle " + std::to_string(n.cycle) + "; restarted");
        break;
      case FeedEvent::cannot_open: sink("setpoint: cannot open the servo stream pipe " + pipe + "; retrying"); break;
    }
  }
}

ServoAlignment ServoSetPointSource::alignment() const {
  ServoAlignment a;
  a.servo_rate_hz = options_.stream.servo_rate_hz;
  if (!daq_clock_.known() || !reader_.clock().known()) return a;
  a.known = true;
  a.servo_cycle_at_sample0 = reader_.clock().number_at(daq_clock_.time_ns(0));
  a.daq_delay_ms = daq_delay_ms_.load(std::memory_order_relaxed);
  return a;
}

}  // namespace eical::drivers
