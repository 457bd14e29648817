#include "drivers/source/linuxcnc_source.hpp"

#include "drivers/source/stamped_source.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <vector>

namespace eical::drivers {
namespace {

void store_max(std::atomic<double>& a, double v) noexcept {
  if (v > a.load(std::memory_order_relaxed)) a.store(v, std::memory_order_relaxed);
}

}  // namespace

LinuxcncSource::LinuxcncSource(sim::Scenario scenario, LinuxcncSourceOptions options)
    : scenario_(std::move(scenario)), options_(std::move(options)) {
  const WindowedSim probe(scenario_, options_.window);  // validates the scenario now (--check)
  ratio_ = probe.ratio();
  ring_ = std::make_unique<SpscRing<dsp::Frame>>(options_.ring_frames);
  const auto hold_frames = static_cast<std::size_t>(std::ceil(options_.hold_s * scenario_.meta.acquisition.fs_hz));
  held_ = std::make_unique<FixedQueue<dsp::Frame>>(
      hold_frames + 2 * probe.frames_per_block() +
      static_cast<std::size_t>(ratio_) * (options_.window.lookahead_cycles + 2 * options_.max_fill_cycles) + 1024);
  markers_ = std::make_unique<SpscRing<MarkerEvent>>(256);
  ServoStreamOptions so;
  so.fifo = options_.fifo;
  so.servo_rate_hz = options_.window.servo_rate_hz;
  so.max_fill_cycles = options_.max_fill_cycles;
  reader_ = std::make_unique<ServoStreamReader>(so);
}

LinuxcncSource::~LinuxcncSource() {
  stop_worker();
  // The stream's summary (the end-to-end test reads it from the journal).
  if (ran_) std::fprintf(stderr, "%s\n", summary().c_str());
}

void LinuxcncSource::stop_worker() {
  if (worker_.joinable()) {
    reader_->wake();
    worker_.join();
  }
  reader_->close();
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
  reader_->open();
  {
    std::lock_guard lk(mu_);
    error_.clear();
    first_line_ = false;
  }
  for (auto* a :
       {&shared_.lines, &shared_.lost_cycles, &shared_.overrun_lines, &shared_.dropped_frames, &shared_.blocks})
    a->store(0);
  shared_.first_number.store(-1);
  failed_.store(false);
  first_number_.store(-1);
  while (available_.try_acquire()) {
  }
  dsp::Frame f;
  while (ring_->try_pop(f)) {
  }
  held_->clear();
  ran_ = true;
  worker_ = std::thread([this] { work(); });

  const std::string path = options_.fifo.string();
  std::unique_lock lk(mu_);
  const bool got = cv_.wait_for(lk, std::chrono::duration<double>(options_.connect_timeout_s),
                                [&] { return first_line_ || !error_.empty(); });
  if (!error_.empty() || !got) {
    const std::string why =
        !error_.empty() ? "linuxcnc: " + error_
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
  if (first < 0 || !reader_->clock().known()) return 0;
  return reader_->clock().time_ns(first + sample_index / ratio_) +
         (sample_index % ratio_) * static_cast<std::int64_t>(1e9 / scenario_.meta.acquisition.fs_hz);
}

LinuxcncStreamStats LinuxcncSource::stats() const {
  LinuxcncStreamStats s;
  s.lines = shared_.lines.load(), s.lost_cycles = shared_.lost_cycles.load(),
  s.overrun_lines = shared_.overrun_lines.load();
  s.dropped_frames = shared_.dropped_frames.load(), s.blocks = shared_.blocks.load();
  s.first_number = shared_.first_number.load(), s.clock_offset_ns = shared_.clock_offset_ns.load();
  s.mean_delay_ms = shared_.mean_delay_ms.load(), s.max_delay_ms = shared_.max_delay_ms.load();
  s.max_block_sim_ms = shared_.max_block_sim_ms.load(),
  s.max_following_error_mm = shared_.max_following_error_mm.load();
  return s;
}

SourceCounters LinuxcncSource::counters() const {
  SourceCounters c;
  c.lost_samples = shared_.lost_cycles.load(std::memory_order_relaxed) * static_cast<std::uint64_t>(ratio_);
  c.dropped_frames = shared_.dropped_frames.load(std::memory_order_relaxed);
  return c;
}

void LinuxcncSource::drain_diagnostics(const std::function<void(const std::string&)>& sink) {
  MarkerEvent m{};
  while (markers_->try_pop(m)) {
    char line[160];
    std::snprintf(line, sizeof line, "linuxcnc: M-code marker %u at servo cycle %lld = sample %lld", m.marker,
                  static_cast<long long>(m.cycle), static_cast<long long>(m.sample));
    sink(line);
  }
}

std::string LinuxcncSource::summary() const {
  const LinuxcncStreamStats s = stats();
  char line[512];
  std::snprintf(
      line, sizeof line,
      "<6>linuxcnc: %llu lines, %llu cycles lost, %llu overrun lines, %llu frames dropped, %llu blocks (longest %.1f "
      "ms); "
      "servo clock: cycle 0 at %lld ns CLOCK_MONOTONIC, lines %.2f ms (mean) / %.2f ms (max) behind their cycle; "
      "max |cmd - fb| %.4f mm",
      static_cast<unsigned long long>(s.lines), static_cast<unsigned long long>(s.lost_cycles),
      static_cast<unsigned long long>(s.overrun_lines), static_cast<unsigned long long>(s.dropped_frames),
      static_cast<unsigned long long>(s.blocks), s.max_block_sim_ms, static_cast<long long>(s.clock_offset_ns),
      s.mean_delay_ms, s.max_delay_ms, s.max_following_error_mm);
  return line;
}

void LinuxcncSource::publish(const ServoStreamReader& reader, const LinuxcncStreamStats& local) {
  const auto& rs = reader.stats();
  shared_.lines.store(rs.lines, std::memory_order_relaxed);
  shared_.lost_cycles.store(rs.lost_cycles, std::memory_order_relaxed);
  shared_.overrun_lines.store(rs.overrun_lines, std::memory_order_relaxed);
  shared_.dropped_frames.store(local.dropped_frames, std::memory_order_relaxed);
  shared_.blocks.store(local.blocks, std::memory_order_relaxed);
  shared_.clock_offset_ns.store(reader.clock().offset_ns(), std::memory_order_relaxed);
  shared_.mean_delay_ms.store(reader.clock().mean_delay_ms(), std::memory_order_relaxed);
  shared_.max_delay_ms.store(reader.clock().max_delay_ms(), std::memory_order_relaxed);
  store_max(shared_.max_block_sim_ms, local.max_block_sim_ms);
  store_max(shared_.max_following_error_mm, local.max_following_error_mm);
}

// The worker thread (the DAQ card's processor): reads the servo stream, simulates a block
// whenever one is ready and releases frames once their servo cycle is hold_s old.
class LinuxcncSource::Worker {
 public:
  explicit Worker(LinuxcncSource& src)
      : src_(src),
        reader_(*src.reader_),
        sim_(src.scenario_, src.options_.window),
        frames_(sim_.frames_per_block() +
                static_cast<std::size_t>(sim_.ratio()) * src.options_.window.lookahead_cycles + 16),
        stall_ms_(static_cast<int>(src.options_.stall_timeout_s * 1000.0)),
        // Longer than open()'s wait, so open() reports the absent LinuxCNC in its own words.
        connect_ms_(static_cast<int>(src.options_.connect_timeout_s * 2000.0)),
        hold_ns_(static_cast<std::int64_t>(src.options_.hold_s * 1e9)) {}

  // Reads until stopped, the stream stalls, ends or fails.
  void run() {
    using S = ServoStreamReader::Status;
    for (;;) {
      const bool before_first = src_.first_number_.load(std::memory_order_relaxed) < 0;
      const auto status =
          reader_.read(before_first ? connect_ms_ : stall_ms_, [this](const ServoCycle& c) { on_cycle(c); });
      if (status == S::woken) break;  // stop_worker()
      if (status == S::timeout) {
        src_.fail(before_first ? "no servo samples within the connect timeout"
                               : "no servo samples for " + std::to_string(src_.options_.stall_timeout_s) +
                                     " s (LinuxCNC stalled?)");
        break;
      }
      if (status == S::error || status == S::closed) {
        end_of_stream(status, before_first);
        break;
      }
      release(false);
    }
    src_.publish(reader_, local_);
  }

 private:
  // One servo cycle: the first one starts the clock, a new marker is logged, the position
  // drives the simulation, a ready block is simulated.
  void on_cycle(const ServoCycle& c) {
    const Eigen::Vector3d cmd(c.cmd_mm[0], c.cmd_mm[1], c.cmd_mm[2]), fb(c.fb_mm[0], c.fb_mm[1], c.fb_mm[2]);
    const Eigen::Vector3d pos = src_.options_.drive_from_feedback ? fb : cmd;
    if (!c.filled) local_.max_following_error_mm = std::max(local_.max_following_error_mm, (cmd - fb).norm());
    if (src_.first_number_.load(std::memory_order_relaxed) < 0) first_line(c.number);
    if (c.marker != last_marker_ && c.marker != 0)
      // Diagnostic (EICAL_MARK=1 in the kit): when the M-code script ran, on the DAQ clock.
      (void)src_.markers_->push_or_drop({c.marker, c.number, (c.number - local_.first_number) * src_.ratio_});
    last_marker_ = c.marker;
    sim_.push(pos, cmd, c.filled);
    if (sim_.block_ready()) {
      emit(false);
      src_.publish(reader_, local_);
    }
  }

  // The stream's first line: its cycle number is sample 0; open() stops waiting.
  void first_line(std::int64_t number) {
    src_.first_number_.store(number, std::memory_order_release);
    src_.shared_.first_number.store(number, std::memory_order_relaxed);
    local_.first_number = number;
    {
      std::lock_guard lk(src_.mu_);  // once per stream, not per sample
      src_.first_line_ = true;
    }
    src_.cv_.notify_all();
  }

  // Simulates a block (flush: the last, however short) into the held queue.
  void emit(bool flush) {
    const auto t0 = std::chrono::steady_clock::now();
    const std::size_t n = sim_.simulate_block(frames_, flush);
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    for (std::size_t k = 0; k < n; ++k) {
      if (src_.held_->full()) release(false);  // never drops: a full queue releases its oldest early
      (void)src_.held_->push(frames_[k]);
    }
    local_.blocks = sim_.blocks();
    if (ms > local_.max_block_sim_ms) local_.max_block_sim_ms = ms;
  }

  // Frames wait until their servo cycle is hold_s old: a DDS trigger (eical trigger
  // starts a process and a participant first) must reach eicald before its frame does,
  // or it is clamped onto a later frame. Released as servo lines arrive (every ~10 ms);
  // `all`: every held frame.
  void release(bool all) {
    FixedQueue<dsp::Frame>& held = *src_.held_;
    std::size_t n = 0;
    const std::int64_t now = monotonic_ns();
    while (!held.empty() && (all || held.full() || src_.sample_time_ns(held.front().sample_index) + hold_ns_ <= now)) {
      dsp::Frame f = held.front();
      held.pop();
      if (drop_flag_) f.flags |= dsp::frame_flag::gap_before;
      drop_flag_ = !src_.ring_->push_or_drop(f);
      if (drop_flag_) ++local_.dropped_frames;
      ++n;
    }
    if (n > 0) src_.available_.release();
  }

  // The stream ended (closed or a bad line): the cycles before it still become frames,
  // every frame goes out, then the source fails naming why.
  void end_of_stream(ServoStreamReader::Status status, bool before_first) {
    emit(true);
    release(true);
    src_.publish(reader_, local_);
    if (status == ServoStreamReader::Status::error)
      src_.fail(reader_.error());
    else if (before_first)
      src_.fail("the servo stream closed before its first line (eical-halsampler failed? see LinuxCNC's log)");
    else
      src_.fail("LinuxCNC closed the servo stream after cycle " + std::to_string(reader_.stats().last_number) +
                " (LinuxCNC stopped or eical-halsampler exited)");
  }

  LinuxcncSource& src_;
  ServoStreamReader& reader_;
  WindowedSim sim_;
  std::vector<dsp::Frame> frames_;
  const int stall_ms_, connect_ms_;
  const std::int64_t hold_ns_;
  bool drop_flag_ = false;
  std::uint32_t last_marker_ = 0;
  LinuxcncStreamStats local_;
};

void LinuxcncSource::work() { Worker(*this).run(); }

}  // namespace eical::drivers
