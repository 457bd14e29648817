#pragma once
// The evaluation thread: takes finished recordings from the recording thread (written to
// disk as they were measured: RecordingWriter) and, as a flat list of stages, names the run
// (metadata, id), puts the NC's set-point on it when it comes from elsewhere (servo
// stream: the clocks' alignment; program: the program M101 named, reconstructed and
// aligned — these two read the recording back into memory), renames it into place
// (durable first), analyses it as it streams from disk (bounded memory whatever its
// length), writes result.json and publishes Result and Trace; then tells the DSP thread
// (RecordingHandoff) that the next recording may come. Not real-time: it allocates and writes.
#include "daemon/config/daemon_config.hpp"
#include "daemon/service/recording_handoff.hpp"
#include "daemon/service/recording_writer.hpp"
#include "dsp/analysis/analyze_run.hpp"
#include "dsp/core/run.hpp"

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <utility>
#include <vector>

namespace eical::drivers {
class ServoSetPointSource;
}

namespace eical::daemon {

class HmiLink;
class HistoryHook;

// Where results go besides the run directory, and what the set-point may come from.
struct EvaluatorLinks {
  HmiLink* hmi = nullptr;                               // Result and Trace (none without DDS)
  const drivers::ServoSetPointSource* servo = nullptr;  // the servo stream's clock alignment
  HistoryHook* history = nullptr;                       // [history] enabled
  std::string sensor_calibration = "datasheet";         // provenance in Result
  const std::atomic<bool>* stop = nullptr;              // the service's stop: ends write retries
  std::vector<std::filesystem::path> unevaluated;       // runs written before a restart without result.json
};

// What the evaluations did, for Status (evaluation thread writes, status thread reads).
struct EvaluationStatus {
  std::uint64_t results = 0;
  std::string last_result;  // path of the last result.json
  std::string fault;        // the last recording or evaluation error
};

class Evaluator {
 public:
  Evaluator(const DaemonConfig& config, dsp::RunMeta meta, dsp::AnalysisOptions analysis, RecordingStream& stream,
            RecordingHandoff& handoff, EvaluatorLinks links);
  ~Evaluator();  // finish()
  // Evaluates what was handed over, then stops the thread; status() stays readable.
  void finish();
  Evaluator(const Evaluator&) = delete;
  Evaluator& operator=(const Evaluator&) = delete;

  [[nodiscard]] EvaluationStatus status() const;
  void set_fault(const std::string& fault);
  // Clears Status.fault when it is still `fault` (a later, other error stays).
  void clear_fault(const std::string& fault);

  // A failed recording write is tried again this often while the service runs.
  static constexpr double kWriteRetryS = 1.0;

 private:
  void loop();
  void evaluate(RecordedRun& job);
  // A run of the previous eicald that has no result.json: evaluated now, flagged.
  void evaluate_recorded(const std::filesystem::path& dir);
  // result.json written: counted, into the history, published.
  void finish_result(const dsp::Run& run, const dsp::Analysis& a, const std::filesystem::path& dir);
  // The run's metadata and name (no frames: they are on disk).
  dsp::Run make_run(const RecordedRun& job) const;
  // Names the recording and renames it into place; with a set-point from elsewhere, reads it
  // back to put that on (flags for the result: empty, nothing doubtful).
  std::vector<dsp::Flag> commit(RecordedRun& job, dsp::Run& run, const std::filesystem::path& dir);
  // The flags only the service knows: how it ended, the guard, the set-point, the source's rate,
  // the temperatures, frames the recorder lost.
  void add_service_flags(const RecordedRun& job, const dsp::Run& run, const std::vector<dsp::Flag>& setpoint_flags,
                         dsp::Analysis& a) const;
  // The program M101's P word (or [setpoint.program] default_program) names.
  std::optional<std::pair<int, dsp::Program>> named_program(const RecordingNotes& notes,
                                                            std::vector<dsp::Flag>& flags) const;
  // Fills cmd_*, [program] and [setpoint]; returns flags for the result (empty: nothing doubtful).
  std::vector<dsp::Flag> add_setpoint(dsp::Run& run, const RecordingNotes& notes) const;
  void publish(const dsp::Run& run, const dsp::Analysis& a, const std::filesystem::path& dir,
               std::uint64_t result_number);
  // Runs `write` until it succeeds (a fault of the storage clears); throws its last error when
  // the service stops first, and bad input (dsp::InputError) at once.
  void write_retrying(const std::string& what, const std::function<void()>& write);
  [[nodiscard]] bool stopping() const;

  const DaemonConfig& config_;
  dsp::RunMeta meta_;
  dsp::AnalysisOptions analysis_;
  RecordingHandoff& handoff_;
  EvaluatorLinks links_;
  mutable std::mutex mu_;
  EvaluationStatus status_;
  RecordingWriter writer_;  // before thread_: running while the evaluation thread runs
  std::thread thread_;
};

}  // namespace eical::daemon
