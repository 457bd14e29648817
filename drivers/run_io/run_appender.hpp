#pragma once
// An eical-run/1 directory written as its frames come (eicald's recorder): samples.csv(.gz)
// grows in a temporary sibling directory (".eicald-recording.tmp-<n>", which
// clean_recording_dir() removes after a crash), then run.toml goes in and the directory is
// renamed into place whole, as write_run() does: a reader never sees half a run.
//
// The samples go out in chunks of about a megabyte of text, each its own gzip member when
// compressed (zlib, gzip and Python read concatenated members as one stream). A chunk that
// cannot be written (disk full, the directory removed) is held in memory and written again
// at the same offset by write_held(); the temporary directory removed meanwhile is made
// again from the samples file still open. Nothing appended is lost while the process lives.
//
// Not for a real-time thread: it allocates, compresses and writes.
#include "dsp/core/run.hpp"

#include <zlib.h>

#include <cstddef>
#include <deque>
#include <filesystem>
#include <string>
#include <vector>

namespace eical::drivers {

class RunAppender {
 public:
  // The run's metadata and channels decide the samples' columns (as write_run()); nothing
  // is created before the first chunk is written.
  RunAppender(std::filesystem::path parent, dsp::RunMeta meta, dsp::ChannelPresence channels, bool gzip);
  ~RunAppender();  // a temporary directory not committed is removed
  RunAppender(const RunAppender&) = delete;
  RunAppender& operator=(const RunAppender&) = delete;

  // One frame; a full chunk is written, or held when it cannot be. Never throws for I/O.
  void append(const dsp::Frame& f);
  // Writes the chunks held; false (error() says why) while some cannot be. Never throws.
  bool write_held();
  [[nodiscard]] const std::string& error() const noexcept { return error_; }
  [[nodiscard]] std::size_t held_bytes() const noexcept;
  [[nodiscard]] std::size_t frames() const noexcept { return frames_; }

  // Every frame appended written and fsynced. Throws std::runtime_error (what could not be
  // written stays held: call again).
  void finish_samples();
  // The frames back from the samples written (a set-point put on afterwards needs them all).
  [[nodiscard]] dsp::Run load() const;
  // The samples replaced by these frames' (the program's set-point put on them).
  void rewrite(const dsp::Run& run);
  // run.toml for `meta`, then the directory renamed to `dir` (which must not exist).
  // Throws std::runtime_error; may be called again. After a commit, called again when
  // `dir` was removed meanwhile: the run is made again from the samples still open.
  void commit(const dsp::RunMeta& meta, const std::filesystem::path& dir);
  [[nodiscard]] const std::filesystem::path& committed_dir() const noexcept { return committed_; }

 private:
  void seal();         // the text so far into a chunk (held until written)
  void ensure_file();  // the temporary directory and the samples file (made again when gone)
  void relocate();     // a new temporary directory, the samples copied from the open file
  [[nodiscard]] std::filesystem::path samples_path() const;

  std::filesystem::path parent_, tmp_, committed_;
  dsp::RunMeta meta_;
  dsp::ChannelPresence channels_;
  bool gzip_;
  std::string samples_name_;
  int fd_ = -1;
  std::size_t written_ = 0;  // bytes of the samples file that hold whole chunks
  std::size_t frames_ = 0;
  std::string text_;                             // rows not yet sealed
  std::deque<std::vector<unsigned char>> held_;  // sealed chunks not yet written, in order
  std::string error_;
  z_stream z_{};
  bool z_ready_ = false;
  bool synced_ = false;  // the samples file fsynced since the last write
};

}  // namespace eical::drivers
