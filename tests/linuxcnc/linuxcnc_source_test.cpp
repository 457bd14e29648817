// The linuxcnc source without LinuxCNC: the test writes the kit's servo stream into the
// named pipe itself.
#include "drivers/source/linuxcnc_source.hpp"
#include "drivers/source/servo_stream.hpp"

#include <gtest/gtest.h>

#include <fcntl.h>
#include <unistd.h>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <random>

namespace eical::drivers {
namespace {

namespace fs = std::filesystem;

fs::path scratch_fifo() {
  const fs::path d = fs::temp_directory_path() / ("eical-lcnc-src-" + std::to_string(std::random_device{}()));
  fs::create_directories(d);
  return d / "servo.fifo";
}

LinuxcncSourceOptions options(const fs::path& fifo) {
  LinuxcncSourceOptions o;
  o.fifo = fifo;
  o.connect_timeout_s = 0.5;
  o.window.block_cycles = 50;
  o.window.history_cycles = 50;
  return o;
}

TEST(ServoStream, ParsesTheKitsLinesAndNamesWhatIsWrong) {
  std::string err;
  const auto l = parse_servo_line("12 1.5 -2.000000 0 1.4 -1.9 0 101 ", err);
  ASSERT_TRUE(l) << err;
  EXPECT_EQ(l->sample.number, 12);
  EXPECT_DOUBLE_EQ(l->sample.cmd_mm[0], 1.5);
  EXPECT_DOUBLE_EQ(l->sample.fb_mm[1], -1.9);
  EXPECT_EQ(l->sample.marker, 101u);
  EXPECT_EQ(parse_servo_line("overrun", err)->kind, ServoLine::Kind::overrun);
  EXPECT_FALSE(parse_servo_line("12 1.5 x 0 1 1 0 0", err));
  EXPECT_NE(err.find("column 3 (cmd Y)"), std::string::npos) << err;
  EXPECT_FALSE(parse_servo_line("12 1 2 3", err));
  EXPECT_FALSE(parse_servo_line("12 1 2 3 4 5 6 7 8", err));
  EXPECT_NE(err.find("more than 8 columns"), std::string::npos) << err;
  EXPECT_FALSE(parse_servo_line("1.5 1 2 3 4 5 6 7", err));
  EXPECT_NE(err.find("sample number"), std::string::npos) << err;
}

TEST(SampleClock, TheFreshestLineOfABurstSetsTheOffset) {
  SampleClock c(1e-3, 100);
  // Lines of cycles 0..9 all arrive together at 10.2 ms (a halsampler burst).
  for (int k = 0; k < 10; ++k) c.observe(k, 10'200'000);
  EXPECT_EQ(c.time_ns(9), 10'200'000);
  EXPECT_EQ(c.time_ns(0), 1'200'000);
  c.observe(10, 10'300'000);  // fresher: arrived 0.3 ms after its cycle at 10 ms
  EXPECT_EQ(c.time_ns(10), 10'300'000);
}

TEST(LinuxcncSource, WithoutLinuxCncOpenFailsNamingThePipeAndTheKit) {
  const fs::path fifo = scratch_fifo();
  LinuxcncSource src(sim::gcode_scenario("", eical::dsp::ProgramKind::freeform, 1), options(fifo));
  const auto t0 = std::chrono::steady_clock::now();
  try {
    src.open();
    FAIL() << "opened without a writer";
  } catch (const SourceError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(fifo.string()), std::string::npos) << what;
    EXPECT_NE(what.find("is LinuxCNC running"), std::string::npos) << what;
  }
  EXPECT_LT(std::chrono::steady_clock::now() - t0, std::chrono::seconds(3)) << "must not hang";
  EXPECT_TRUE(fs::is_fifo(fifo)) << "the source creates the pipe the kit writes";
}

TEST(LinuxcncSource, RefusesAPathThatIsNotAPipe) {
  const fs::path fifo = scratch_fifo();
  std::FILE* f = std::fopen(fifo.c_str(), "w");
  ASSERT_NE(f, nullptr);
  std::fclose(f);
  LinuxcncSource src(sim::gcode_scenario("", eical::dsp::ProgramKind::freeform, 1), options(fifo));
  EXPECT_THROW(src.open(), SourceError);
}

TEST(LinuxcncSource, StreamedCyclesBecomeFramesAndAMalformedLineFailsTheSource) {
  const fs::path fifo = scratch_fifo();
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0666), 0);
  // The writer end, read-write as eical-halsampler opens it.
  const int w = ::open(fifo.c_str(), O_RDWR);
  ASSERT_GE(w, 0);
  std::string lines;
  for (int k = 0; k < 400; ++k) {
    char l[128];
    std::snprintf(l, sizeof l, "%d %.6f 0.000000 0.000000 %.6f 0.000000 0.000000 0 \n", 1000 + k, k * 0.01, k * 0.01);
    lines += l;
  }
  lines += "1400 0.5 0 0 0.5 0 0 zzz\n";
  ASSERT_EQ(::write(w, lines.data(), lines.size()), static_cast<ssize_t>(lines.size()));

  LinuxcncSource src(sim::gcode_scenario("", eical::dsp::ProgramKind::freeform, 1), options(fifo));
  src.open();
  std::vector<dsp::Frame> out(4096);
  std::size_t frames = 0;
  std::string error;
  try {
    for (int i = 0; i < 100; ++i) {
      const std::size_t n = src.read(out);
      for (std::size_t k = 0; k < n; ++k) ASSERT_EQ(out[k].sample_index, static_cast<std::int64_t>(frames + k));
      frames += n;
    }
  } catch (const SourceError& e) {
    error = e.what();
  }
  ::close(w);
  EXPECT_NE(error.find("malformed servo line 401"), std::string::npos) << error;
  EXPECT_NE(error.find("mcode-marker"), std::string::npos) << error;
  // 400 cycles at 1 kHz → 10 frames each, the first cycle on frame 0.
  EXPECT_EQ(frames, 399u * 10u + 1u);
  EXPECT_NE(src.sample_time_ns(0), 0) << "the servo clock was observed";
  EXPECT_EQ(src.sample_time_ns(10) - src.sample_time_ns(0), 1'000'000) << "one servo cycle = 10 frames = 1 ms";
  EXPECT_EQ(src.stats().first_number, 1000);
}

}  // namespace
}  // namespace eical::drivers
