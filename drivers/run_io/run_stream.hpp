#pragma once
// A recorded run read as it streams: run.toml, truth.toml and the samples' header now,
// the frames each time they are replayed (samples.csv read again; one row in memory).
// What eical analyze and eicald's evaluation read a run with, so that a 10-minute
// recording costs no more memory than a 10-second one (dsp/stream/analyze_stream.hpp).
#include "dsp/stream/analyze_stream.hpp"
#include "dsp/stream/frame_replay.hpp"

#include <filesystem>

namespace eical::drivers {

class RunStream final : public dsp::FrameReplay {
 public:
  // Reads the metadata strictly (InputError naming file, line, field) and the first row.
  explicit RunStream(const std::filesystem::path& dir);

  // The run without its frames (Run::streamed_frames counts them after a replay). Its
  // sensor presence is assumed from the first row until a replay has seen every row.
  [[nodiscard]] dsp::Run& header() noexcept { return header_; }
  void replay(const std::function<void(const dsp::Frame&)>& frame) override;
  [[nodiscard]] std::size_t size_hint() const override { return size_hint_; }
  // After a replay: true when the rows bore out the assumed sensor presence; else the
  // header now holds what they showed (a triplex empty in every row is absent) and the
  // frames must be read again.
  bool presence_held();

 private:
  std::filesystem::path file_;
  dsp::Run header_;
  bool seen_[2] = {false, false};
  bool replayed_ = false;
  std::size_t size_hint_ = 0;
};

// The streamed analysis of a run read as it streams (reading it again when the sensors'
// presence was not what its first row showed). Spills: StreamOptions::spills.
dsp::Analysis analyze_stream(RunStream& run, const dsp::AnalysisOptions& options, const dsp::StreamOptions& stream);

}  // namespace eical::drivers
