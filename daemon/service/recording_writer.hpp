#pragma once
// The recording thread: drains RecordingStream and writes each recording to disk as it is
// measured (drivers::RunAppender: a temporary run directory in the recording directory),
// then hands each finished recording to the evaluation thread, which names it, writes its
// run.toml, renames it into place and analyses it from disk. A write that fails (disk
// full, the directory removed) keeps the rest of the recording in memory, tried again
// every retry_s, and Status.fault says so until it is written: nothing recorded is lost
// while the process lives. Not real-time: it allocates, compresses, writes and waits.
#include "daemon/service/recording_notes.hpp"
#include "daemon/service/recording_stream.hpp"
#include "drivers/run_io/run_appender.hpp"
#include "dsp/core/run_meta.hpp"

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <filesystem>
#include <functional>
#include <limits>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

namespace eical::daemon {

// What the recording thread saw of a recording's frames (the evaluation does not hold them).
struct RecordingStats {
  std::uint64_t frames = 0;
  std::uint64_t cmd_missing = 0;  // frames without the NC's set-point
  std::uint64_t lost = 0;         // frames the ring had no room for (not recorded)
  std::int64_t first_index = 0;   // sample index of the first frame
  // Each sensor's case temperature range over the frames that carry one (lo > hi: none).
  static constexpr float kNone = std::numeric_limits<float>::infinity();
  float temp_lo_c[2] = {kNone, kNone}, temp_hi_c[2] = {-kNone, -kNone};
  void add(const dsp::Frame& f) noexcept;
};

struct RecordedRun {
  std::unique_ptr<drivers::RunAppender> run;  // its samples written (or held), not yet named
  RecordingNotes notes;
  std::optional<dsp::Flag> cause;  // why it ended without M103, when it did
  RecordingStats stats;
  bool handed_over = true;  // ended by the DSP thread's hand-over (false: cut off at the stop)
};

class RecordingWriter {
 public:
  // fault(text, true) sets Status.fault, fault(text, false) clears it when it is still that.
  using FaultHook = std::function<void(const std::string& text, bool set)>;
  RecordingWriter(std::filesystem::path dir, dsp::RunMeta meta, bool gzip, RecordingStream& stream, FaultHook fault,
                  double retry_s);
  ~RecordingWriter();  // finish()
  RecordingWriter(const RecordingWriter&) = delete;
  RecordingWriter& operator=(const RecordingWriter&) = delete;

  // Evaluation thread: the next finished recording (waits); false once finish() has drained
  // everything and none is left.
  bool next(RecordedRun& out);
  // After the DSP thread's last frame: drains what it handed over, then stops the thread.
  void finish();

 private:
  void loop();
  void drain();
  void on_event(const RecordEvent& e);
  void deliver(RecordedRun run);
  void retry_held();

  std::filesystem::path dir_;
  dsp::RunMeta meta_;
  dsp::ChannelPresence channels_;
  bool gzip_;
  RecordingStream& stream_;
  FaultHook fault_;
  double retry_s_;
  std::unique_ptr<RecordedRun> open_;                   // recording thread: the recording being written
  std::string fault_text_;                              // recording thread: the fault it reported (empty: none)
  std::chrono::steady_clock::time_point next_retry_{};  // recording thread
  std::mutex mu_;
  std::condition_variable cv_;
  std::deque<RecordedRun> finished_;
  bool stopped_ = false;
  std::atomic<bool> quit_{false};
  std::thread thread_;
};

}  // namespace eical::daemon
