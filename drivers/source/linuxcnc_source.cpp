#include "drivers/source/linuxcnc_source.hpp"

#include "drivers/source/servo_stream.hpp"
#include "drivers/source/stamped_source.hpp"

#include <cerrno>
#include <deque>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fcntl.h>
#include <poll.h>
#include <sys/eventfd.h>
#include <sys/stat.h>
#include <unistd.h>
#include <vector>

namespace eical::drivers {

LinuxcncSource::LinuxcncSource(sim::Scenario scenario, LinuxcncSourceOptions options)
    : scenario_(std::move(scenario)), options_(std::move(options)) {
  ratio_ = WindowedSim(scenario_, options_.window).ratio();  // validates the scenario now (--check)
  ring_ = std::make_unique<SpscRing<dsp::Frame>>(options_.ring_frames);
}

LinuxcncSource::~LinuxcncSource() { stop_worker(); }

void LinuxcncSource::stop_worker() {
  if (worker_.joinable()) {
    const std::uint64_t one = 1;
    (void)!::write(wake_fd_, &one, sizeof one);
    worker_.join();
  }
  if (fd_ >= 0) ::close(fd_), fd_ = -1;
  if (wake_fd_ >= 0) ::close(wake_fd_), wake_fd_ = -1;
}

void LinuxcncSource::fail(const std::string& why) {
  {
    std::lock_guard lk(mu_);
    if (error_.empty()) error_ = why;  // read() → pump names the source; open() adds the prefix
  }
  failed_.store(true, std::memory_order_release);
  cv_.notify_all();
  available_.release();
}

void LinuxcncSource::open() {
  stop_worker();
  const std::string path = options_.fifo.string();
  struct stat st{};
  if (::stat(path.c_str(), &st) != 0) {
    if (errno != ENOENT) throw SourceError("linuxcnc: " + path + ": " + std::strerror(errno));
    std::error_code ec;
    std::filesystem::create_directories(options_.fifo.parent_path(), ec);
    // 0666: eical-halsampler runs as LinuxCNC's user; the umask is overridden by chmod.
    if (::mkfifo(path.c_str(), 0666) != 0 && errno != EEXIST)
      throw SourceError("linuxcnc: cannot create the servo stream pipe " + path + ": " + std::strerror(errno));
    (void)::chmod(path.c_str(), 0666);
  } else if (!S_ISFIFO(st.st_mode)) {
    throw SourceError("linuxcnc: " + path + " exists and is not a named pipe (remove it; eicald creates the pipe)");
  }
  // Non-blocking open: a pipe without a writer (LinuxCNC not running) must not hang here.
  fd_ = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd_ < 0) throw SourceError("linuxcnc: cannot open " + path + ": " + std::strerror(errno));
  wake_fd_ = ::eventfd(0, EFD_CLOEXEC);
  if (wake_fd_ < 0) throw SourceError(std::string("linuxcnc: eventfd: ") + std::strerror(errno));
  {
    std::lock_guard lk(mu_);
    error_.clear();
    stats_ = {};
    first_line_ = false;
  }
  failed_.store(false);
  first_number_.store(-1);
  while (available_.try_acquire()) {
  }
  dsp::Frame f;
  while (ring_->try_pop(f)) {
  }
  clock_ = std::make_unique<ServoClock>(1.0 / options_.window.servo_rate_hz);
  worker_ = std::thread([this, fd = fd_] { work(fd); });

  std::unique_lock lk(mu_);
  const bool got = cv_.wait_for(lk, std::chrono::duration<double>(options_.connect_timeout_s), [&] { return first_line_ || !error_.empty(); });
  if (!error_.empty() || !got) {
    const std::string why = !error_.empty() ? "linuxcnc: " + error_
                                            : "no servo samples on " + path + " within " + std::to_string(options_.connect_timeout_s) +
                                                  " s: is LinuxCNC running with the eical kit (eical_sampler.hal loads eical-halsampler, "
                                                  "which writes this pipe)?";
    lk.unlock();
    stop_worker();
    throw SourceError(why);
  }
}

std::size_t LinuxcncSource::read(std::span<dsp::Frame> out) {
  std::size_t n = ring_->pop_many(out);
  if (n > 0) return n;
  if (failed_.load(std::memory_order_acquire)) {
    n = ring_->pop_many(out);  // the last frames before the failure first
    if (n > 0) return n;
    std::lock_guard lk(mu_);
    throw SourceError(error_);
  }
  // Bounded wait: the pump checks its stop flag between reads.
  if (available_.try_acquire_for(std::chrono::milliseconds(100))) n = ring_->pop_many(out);
  return n;
}

std::int64_t LinuxcncSource::sample_time_ns(std::int64_t sample_index) const {
  const std::int64_t first = first_number_.load(std::memory_order_acquire);
  if (first < 0 || !clock_) return 0;
  return clock_->time_ns(first + sample_index / ratio_) + (sample_index % ratio_) * static_cast<std::int64_t>(1e9 / scenario_.meta.acquisition.fs_hz);
}

LinuxcncStreamStats LinuxcncSource::stats() const {
  std::lock_guard lk(mu_);
  return stats_;
}

void LinuxcncSource::work(int fd) {
  WindowedSim sim(scenario_, options_.window);
  std::vector<dsp::Frame> frames(sim.frames_per_block() + static_cast<std::size_t>(sim.ratio()) * options_.window.lookahead_cycles + 16);
  std::vector<char> buf(1 << 16);
  std::size_t used = 0;
  std::int64_t last_number = -1;
  Eigen::Vector3d last_pos = Eigen::Vector3d::Zero(), last_cmd = Eigen::Vector3d::Zero();
  bool drop_flag = false;
  std::uint32_t last_marker = 0;
  std::deque<dsp::Frame> held;
  LinuxcncStreamStats local;
  const int stall_ms = static_cast<int>(options_.stall_timeout_s * 1000.0);
  // Longer than open()'s wait, so open() reports the absent LinuxCNC in its own words.
  const int connect_ms = static_cast<int>(options_.connect_timeout_s * 2000.0);

  auto emit = [&](bool flush) {
    const auto t0 = std::chrono::steady_clock::now();
    const std::size_t n = sim.simulate_block(frames, flush);
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    held.insert(held.end(), frames.begin(), frames.begin() + static_cast<std::ptrdiff_t>(n));
    local.blocks = sim.blocks();
    if (ms > local.max_block_sim_ms) local.max_block_sim_ms = ms;
  };
  // Frames wait until their servo cycle is hold_ms old: a DDS trigger (eical trigger
  // starts a process and a participant first) must reach eicald before its frame does,
  // or it is clamped onto a later frame. Released as servo lines arrive (every ~10 ms).
  const auto hold_ns = static_cast<std::int64_t>(options_.hold_s * 1e9);
  auto release = [&](bool all) {
    std::size_t n = 0;
    const std::int64_t now = monotonic_ns();
    while (!held.empty() && (all || sample_time_ns(held.front().sample_index) + hold_ns <= now)) {
      dsp::Frame& f = held.front();
      if (drop_flag) f.flags |= dsp::frame_flag::gap_before;
      drop_flag = !ring_->push_or_drop(f);
      if (drop_flag) ++local.dropped_frames;
      held.pop_front(), ++n;
    }
    if (n > 0) available_.release();
  };
  auto publish_stats = [&] {
    local.clock_offset_ns = clock_->offset_ns();
    local.mean_delay_ms = clock_->mean_delay_ms();
    local.max_delay_ms = clock_->max_delay_ms();
    std::lock_guard lk(mu_);
    stats_ = local;
  };

  for (;;) {
    pollfd p[2] = {{fd, POLLIN, 0}, {wake_fd_, POLLIN, 0}};
    const int r = ::poll(p, 2, last_number < 0 ? connect_ms : stall_ms);
    if (r < 0) {
      if (errno == EINTR) continue;
      fail(std::string("poll: ") + std::strerror(errno));
      break;
    }
    if (p[1].revents) break;  // stop_worker()
    if (r == 0) {
      fail(last_number < 0 ? "no servo samples within the connect timeout"
                           : "no servo samples for " + std::to_string(options_.stall_timeout_s) + " s (LinuxCNC stalled?)");
      break;
    }
    const ssize_t got = ::read(fd, buf.data() + used, buf.size() - used);
    const std::int64_t arrival_ns = monotonic_ns();
    if (got < 0) {
      if (errno == EAGAIN || errno == EINTR) continue;
      fail(std::string("read: ") + std::strerror(errno));
      break;
    }
    if (got == 0) {
      if (last_number < 0) {
        // POLLHUP before any writer: a writer came and went without a line.
        fail("the servo stream closed before its first line (eical-halsampler failed? see LinuxCNC's log)");
        break;
      }
      emit(true);  // what arrived before the end still becomes frames
      release(true);
      publish_stats();
      fail("LinuxCNC closed the servo stream after cycle " + std::to_string(last_number) + " (LinuxCNC stopped or eical-halsampler exited)");
      break;
    }
    used += static_cast<std::size_t>(got);
    std::size_t start = 0;
    bool broken = false;
    for (std::size_t i = 0; i < used; ++i) {
      if (buf[i] != '\n') continue;
      const std::string_view line(buf.data() + start, i - start);
      start = i + 1;
      std::string error;
      const auto parsed = parse_servo_line(line, error);
      if (!parsed) {
        emit(true);  // the cycles before the bad line still become frames
        release(true);
        fail("malformed servo line " + std::to_string(local.lines + 1) + ": " + error + " in '" + std::string(line.substr(0, 120)) + "'");
        broken = true;
        break;
      }
      ++local.lines;
      if (parsed->kind == ServoLine::Kind::overrun) {
        ++local.overrun_lines;
        continue;
      }
      const ServoSample& s = parsed->sample;
      const Eigen::Vector3d cmd(s.cmd_mm[0], s.cmd_mm[1], s.cmd_mm[2]), fb(s.fb_mm[0], s.fb_mm[1], s.fb_mm[2]);
      const Eigen::Vector3d pos = options_.drive_from_feedback ? fb : cmd;
      local.max_following_error_mm = std::max(local.max_following_error_mm, (cmd - fb).norm());
      clock_->observe(s.number, arrival_ns);
      if (last_number < 0) {
        first_number_.store(s.number, std::memory_order_release);
        local.first_number = s.number;
        {
          std::lock_guard lk(mu_);
          first_line_ = true;
        }
        cv_.notify_all();
      } else if (s.number <= last_number) {
        fail("servo cycle numbers went back from " + std::to_string(last_number) + " to " + std::to_string(s.number) + " (LinuxCNC restarted?)");
        broken = true;
        break;
      } else if (s.number > last_number + 1) {
        const auto lost = static_cast<std::size_t>(s.number - last_number - 1);
        if (lost > options_.max_fill_cycles) {
          fail(std::to_string(lost) + " servo cycles lost after cycle " + std::to_string(last_number) +
               " (more than max_fill_cycles; eicald fell behind or LinuxCNC paused)");
          broken = true;
          break;
        }
        // Lost cycles (HAL sampler overrun): linear fill, frames flagged cmd_missing.
        local.lost_cycles += lost;
        for (std::size_t k = 1; k <= lost; ++k) {
          const double u = static_cast<double>(k) / static_cast<double>(lost + 1);
          sim.push(last_pos + (pos - last_pos) * u, last_cmd + (cmd - last_cmd) * u, true);
          if (sim.block_ready()) emit(false);
        }
      }
      if (s.marker != last_marker && s.marker != 0)
        // Diagnostic (EICAL_MARK=1 in the kit): when the M-code script ran, on the DAQ clock.
        std::fprintf(stderr, "<6>linuxcnc: M-code marker %u at servo cycle %lld = sample %lld\n", s.marker,
                     static_cast<long long>(s.number), static_cast<long long>((s.number - local.first_number) * ratio_));
      last_marker = s.marker;
      last_number = s.number, last_pos = pos, last_cmd = cmd;
      sim.push(pos, cmd);
      if (sim.block_ready()) {
        emit(false);
        publish_stats();
      }
    }
    release(false);
    if (broken) break;
    // Keep the partial line.
    if (start > 0) std::memmove(buf.data(), buf.data() + start, used - start), used -= start;
    if (used == buf.size()) {
      fail("a servo line longer than " + std::to_string(buf.size()) + " bytes: not the kit's stream");
      break;
    }
  }
  publish_stats();
  std::fprintf(stderr,
               "<6>linuxcnc: %llu lines, %llu cycles lost, %llu overrun lines, %llu frames dropped, %llu blocks (longest %.1f ms); "
               "servo clock: cycle 0 at %lld ns CLOCK_MONOTONIC, lines %.2f ms (mean) / %.2f ms (max) behind their cycle; "
               "max |cmd - fb| %.4f mm\n",
               static_cast<unsigned long long>(local.lines), static_cast<unsigned long long>(local.lost_cycles),
               static_cast<unsigned long long>(local.overrun_lines), static_cast<unsigned long long>(local.dropped_frames),
               static_cast<unsigned long long>(local.blocks), local.max_block_sim_ms, static_cast<long long>(local.clock_offset_ns),
               local.mean_delay_ms, local.max_delay_ms, local.max_following_error_mm);
}

}  // namespace eical::drivers
