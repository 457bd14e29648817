#include "daemon/service/recording_writer.hpp"

#include "daemon/system/log.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <span>

namespace eical::daemon {

void RecordingStats::add(const dsp::Frame& f) noexcept {
  if (frames++ == 0) first_index = f.sample_index;
  if (f.flags & dsp::frame_flag::cmd_missing) ++cmd_missing;
  if (f.flags & dsp::frame_flag::temp_missing) return;
  for (int s = 0; s < 2; ++s)
    if (std::isfinite(f.temp_c[s]))
      temp_lo_c[s] = std::min(temp_lo_c[s], f.temp_c[s]), temp_hi_c[s] = std::max(temp_hi_c[s], f.temp_c[s]);
}

RecordingWriter::RecordingWriter(std::filesystem::path dir, dsp::RunMeta meta, bool gzip, RecordingStream& stream,
                                 FaultHook fault, double retry_s)
    : dir_(std::move(dir)),
      meta_(std::move(meta)),
      gzip_(gzip),
      stream_(stream),
      fault_(std::move(fault)),
      retry_s_(retry_s) {
  channels_.psd_count = static_cast<int>(std::min<std::size_t>(meta_.psd.size(), dsp::kMaxPsd));
  thread_ = std::thread([this] { loop(); });
}

RecordingWriter::~RecordingWriter() { finish(); }

void RecordingWriter::finish() {
  if (!thread_.joinable()) return;
  quit_.store(true);
  stream_.wake();
  thread_.join();
}

bool RecordingWriter::next(RecordedRun& out) {
  std::unique_lock lk(mu_);
  cv_.wait(lk, [&] { return stopped_ || !finished_.empty(); });
  if (finished_.empty()) return false;
  out = std::move(finished_.front());
  finished_.pop_front();
  return true;
}

void RecordingWriter::deliver(RecordedRun run) {
  {
    std::lock_guard lk(mu_);
    finished_.push_back(std::move(run));
  }
  cv_.notify_all();
}

void RecordingWriter::loop() {
  for (;;) {
    const bool quitting = quit_.load();  // read before the last drain: what came before it is drained
    drain();
    retry_held();
    if (quitting) break;
    const bool held = open_ && !open_->run->error().empty();
    stream_.wait(std::chrono::milliseconds(held ? static_cast<long>(retry_s_ * 1000.0) : 1000));
  }
  if (open_) {  // begun, never ended nor dropped (the DSP thread stopped inside it): kept all the same
    log(LogLevel::warning, "recording: a measurement without its end at the stop (%llu frames): evaluated as cut short",
        static_cast<unsigned long long>(open_->stats.frames));
    open_->cause =
        dsp::Flag{dsp::FlagCode::interrupted, {}, "the service stopped before the measurement's end was handed over"};
    open_->handed_over = false;
    deliver(std::move(*open_));
    open_.reset();
  }
  {
    std::lock_guard lk(mu_);
    stopped_ = true;
  }
  cv_.notify_all();
}

void RecordingWriter::drain() {
  std::array<dsp::Frame, 4096> block;
  for (;;) {
    RecordEvent event;
    bool has_event = false;
    const std::size_t n = stream_.drain(std::span<dsp::Frame>(block), event, has_event);
    if (open_)
      for (std::size_t k = 0; k < n; ++k) open_->run->append(block[k]), open_->stats.add(block[k]);
    if (has_event) on_event(event);
    if (n == 0 && !has_event) return;
  }
}

void RecordingWriter::on_event(const RecordEvent& e) {
  switch (e.kind) {
    case RecordEvent::Kind::begin:
      if (open_) log(LogLevel::error, "recording: a measurement began before the last one ended; the last one dropped");
      open_ = std::make_unique<RecordedRun>();
      open_->run = std::make_unique<drivers::RunAppender>(dir_, meta_, channels_, gzip_);
      break;
    case RecordEvent::Kind::discard: open_.reset(); break;
    case RecordEvent::Kind::end:
      if (!open_) {
        log(LogLevel::error, "recording: an end without its beginning (ignored)");
        break;
      }
      open_->notes = e.notes;
      open_->stats.lost = e.lost_frames;
      if (e.has_cause) open_->cause = stream_.take_cause();
      deliver(std::move(*open_));
      open_.reset();
      break;
  }
}

// The open recording's chunks that could not be written: again, at most every retry_s
// (append() tries each new chunk too); Status.fault while some are held.
void RecordingWriter::retry_held() {
  using Clock = std::chrono::steady_clock;
  if (open_ && !open_->run->error().empty() && Clock::now() >= next_retry_) {
    next_retry_ = Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(retry_s_));
    (void)open_->run->write_held();
  }
  const std::string now = open_ && !open_->run->error().empty()
                              ? "recording: the measurement being recorded: " + open_->run->error() +
                                    "; retried every " + std::to_string(static_cast<int>(retry_s_)) +
                                    " s, the measurement is held in memory"
                              : std::string();
  if (now == fault_text_) return;
  if (!fault_text_.empty()) {
    fault_(fault_text_, false);
    if (now.empty()) log(LogLevel::notice, "recording: the measurement being recorded is written again");
  }
  if (!now.empty()) {
    log(LogLevel::error, "%s", now.c_str());
    fault_(now, true);
  }
  fault_text_ = now;
}

}  // namespace eical::daemon
