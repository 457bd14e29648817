// A run written as its frames come (eicald's recorder) is the run write_run() writes: the
// same run.toml and samples text (several gzip members read as one stream), renamed into
// place whole; a chunk the disk refuses is held and written when it takes it again; the
// temporary directory or the committed run removed meanwhile is made again from the
// samples file still open.
#include "drivers/run_io/run_appender.hpp"
#include "drivers/run_io/run_reader.hpp"
#include "drivers/run_io/run_stream.hpp"
#include "drivers/run_io/run_writer.hpp"
#include "tests/support/file_size_limit.hpp"
#include "tests/support/temp_dir.hpp"

#include <gtest/gtest.h>
#include <sys/resource.h>
#include <unistd.h>
#include <zlib.h>

#include <cmath>
#include <csignal>
#include <fstream>
#include <iterator>
#include <random>
#include <string>

namespace eical::drivers {
namespace {

namespace fs = std::filesystem;

using test_support::TempDir;

// Longer than one chunk of text (about 1 MB): several gzip members.
dsp::Run long_run(std::size_t frames = 12000) {
  dsp::Run r;
  r.meta.id = "appended-0001";
  r.meta.created = "2026-11-27T10:00:00Z";
  r.meta.program.kind = eical::dsp::ProgramKind::circle;
  r.meta.psd = {dsp::PsdSpec{}};
  r.channels.psd_count = 1;
  for (std::size_t i = 0; i < frames; ++i) {
    dsp::Frame f;
    f.sample_index = static_cast<std::int64_t>(i) + 17;
    for (int c = 0; c < 6; ++c) f.accel_counts[c] = 1000 * c - 7 * static_cast<int>(i % 977);
    f.psd_counts[0] = static_cast<int>(i % 31), f.psd_counts[1] = -static_cast<int>(i % 29);
    f.temp_c[0] = 21.5f, f.temp_c[1] = 22.25f + static_cast<float>(i % 3);
    f.cmd_mm[0] = 150.0 * std::cos(static_cast<double>(i) * 1e-3),
    f.cmd_mm[1] = 150.0 * std::sin(static_cast<double>(i) * 1e-3);
    f.trigger = i == 100 ? 101 : i + 100 == frames ? 103 : 0;
    if (i % 1000 == 500) f.flags |= dsp::frame_flag::cmd_missing;
    r.frames.push_back(f);
  }
  return r;
}

std::string text_of(const fs::path& file) {  // decompressed when it is gzip (every member)
  gzFile gz = gzopen(file.c_str(), "rb");
  std::string out;
  char buf[1 << 16];
  for (int n; (n = gzread(gz, buf, sizeof buf)) > 0;) out.append(buf, static_cast<std::size_t>(n));
  gzclose(gz);
  return out;
}

std::string bytes_of(const fs::path& file) {
  std::ifstream is(file, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(is), std::istreambuf_iterator<char>());
}

void append_all(RunAppender& a, const dsp::Run& run) {
  for (const auto& f : run.frames) a.append(f);
}

TEST(RunAppender, WritesTheRunWriteRunWrites) {
  TempDir tmp;
  const dsp::Run run = long_run();
  for (bool gz : {false, true}) {
    const fs::path whole = tmp.path / (gz ? "whole-gz" : "whole"), streamed = tmp.path / (gz ? "app-gz" : "app");
    write_run(run, whole, {.gzip = gz});
    {
      RunAppender a(tmp.path, run.meta, run.channels, gz);
      append_all(a, run);
      EXPECT_EQ(a.frames(), run.frames.size());
      a.commit(run.meta, streamed);
      EXPECT_EQ(a.committed_dir(), streamed);
    }
    const std::string samples = gz ? "samples.csv.gz" : "samples.csv";
    EXPECT_EQ(bytes_of(whole / "run.toml"), bytes_of(streamed / "run.toml"));
    const std::string text = text_of(streamed / samples);
    EXPECT_EQ(text_of(whole / samples), text);
    EXPECT_GT(text.size(), std::size_t{1} << 20) << "more than one chunk";
    const dsp::Run back = read_run(streamed);
    ASSERT_EQ(back.frames.size(), run.frames.size());
    EXPECT_EQ(back.frames.back().sample_index, run.frames.back().sample_index);
    // Read as it streams, the reserve comes near the rows (several gzip members too).
    RunStream stream(streamed);
    EXPECT_GT(stream.size_hint(), run.frames.size() * 8 / 10);
    EXPECT_LT(stream.size_hint(), run.frames.size() * 14 / 10);
  }
  std::size_t entries = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(tmp.path)) ++entries;
  EXPECT_EQ(entries, 4u) << "no temporary left";
}

using eical::testing::FileSizeLimit;

TEST(RunAppender, AChunkTheDiskRefusesIsHeldAndWrittenWhenItTakesItAgain) {
  TempDir tmp;
  const dsp::Run run = long_run(30000);
  RunAppender a(tmp.path, run.meta, run.channels, true);
  {
    FileSizeLimit full(64 * 1024);
    append_all(a, run);
    EXPECT_NE(a.error().find("write failed"), std::string::npos) << a.error();
    EXPECT_GT(a.held_bytes(), 0u);
    EXPECT_FALSE(a.write_held());
    EXPECT_THROW(a.commit(run.meta, tmp.path / "run"), std::runtime_error);
  }
  EXPECT_TRUE(a.write_held()) << a.error();
  EXPECT_TRUE(a.error().empty());
  a.commit(run.meta, tmp.path / "run");
  const dsp::Run back = read_run(tmp.path / "run");
  ASSERT_EQ(back.frames.size(), run.frames.size());
  for (std::size_t i = 0; i < run.frames.size(); i += 997) EXPECT_EQ(back.frames[i].cmd_mm[0], run.frames[i].cmd_mm[0]);
}

TEST(RunAppender, ARemovedDirectoryIsMadeAgainFromTheOpenSamples) {
  TempDir tmp;
  const dsp::Run run = long_run();
  const fs::path parent = tmp.path / "runs";
  RunAppender a(parent, run.meta, run.channels, true);
  for (std::size_t i = 0; i < run.frames.size() / 2; ++i) a.append(run.frames[i]);
  fs::remove_all(parent);  // the recording directory removed while recording
  for (std::size_t i = run.frames.size() / 2; i < run.frames.size(); ++i) a.append(run.frames[i]);
  a.commit(run.meta, parent / "run");
  EXPECT_EQ(read_run(parent / "run").frames.size(), run.frames.size());
  fs::remove_all(parent);  // and again after the commit: committed again, whole
  a.commit(run.meta, parent / "run");
  EXPECT_EQ(read_run(parent / "run").frames.size(), run.frames.size());
}

TEST(RunAppender, ReadBackAndRewrittenWithAnotherSetPoint) {
  TempDir tmp;
  const dsp::Run run = long_run(3000);
  RunAppender a(tmp.path, run.meta, run.channels, false);
  append_all(a, run);
  a.finish_samples();
  dsp::Run back = a.load();
  ASSERT_EQ(back.frames.size(), run.frames.size());
  for (auto& f : back.frames) f.cmd_mm[2] = 1.25, f.flags &= ~dsp::frame_flag::cmd_missing;
  a.rewrite(back);
  a.commit(run.meta, tmp.path / "run");
  const dsp::Run again = read_run(tmp.path / "run");
  ASSERT_EQ(again.frames.size(), run.frames.size());
  for (const auto& f : again.frames) ASSERT_EQ(f.cmd_mm[2], 1.25);
}

TEST(RunAppender, ARunNotCommittedLeavesNothing) {
  TempDir tmp;
  const dsp::Run run = long_run();
  {
    RunAppender a(tmp.path, run.meta, run.channels, true);
    append_all(a, run);
  }
  EXPECT_TRUE(fs::is_empty(tmp.path));
}

}  // namespace
}  // namespace eical::drivers
