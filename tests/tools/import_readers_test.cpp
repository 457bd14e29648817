// The importers' readers are strict: every bad row is file:line: column: reason; the
// uniform clock recovers the rate from stamps printed to 1 us, the gaps and the jitter.
#include "drivers/import/capture_files.hpp"
#include "drivers/import/uniform_clock.hpp"
#include "drivers/run_io/run_writer.hpp"
#include "dsp/core/error.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <random>

namespace eical::drivers {
namespace {

namespace fs = std::filesystem;

std::string file_with(const std::string& name, const std::string& text) {
  const fs::path p = fs::temp_directory_path() / ("eical-readers-" + std::to_string(::getpid()) + "-" + name);
  write_text_atomic(p, text);
  return p.string();
}

template <class F>
std::string error_of(F&& read) {
  try {
    read();
  } catch (const dsp::InputError& e) {
    return e.what();
  }
  return "no error";
}

constexpr const char* kHeader = "#time,accel_x,accel_y,accel_z\n";

TEST(ImportReaders, KlipperCaptureRowsAreCheckedOneByOne) {
  auto klipper = [](const std::string& name, const std::string& text) {
    const std::string f = file_with(name, text);
    return error_of([&] { read_klipper_capture(f); });
  };
  EXPECT_NE(klipper("empty", "").find("empty file"), std::string::npos);
  EXPECT_NE(klipper("header", "time,x,y,z\n1,2,3,4\n").find(":1: expected Klipper's header"), std::string::npos);
  EXPECT_NE(klipper("norows", kHeader).find("no samples after the header"), std::string::npos);
  const std::string nan = klipper("nan", std::string("##stats\n") + kHeader + "1.000000,1,2,3\n1.000312,nan,2,3\n");
  EXPECT_NE(nan.find(":4: column 'accel_x': NaN or Inf"), std::string::npos) << nan;
  EXPECT_NE(klipper("word", std::string(kHeader) + "1.0,1,abc,3\n")
                .find(":2: column 'accel_y': expected a number, got 'abc'"),
            std::string::npos);
  EXPECT_NE(klipper("back", std::string(kHeader) + "1.0,1,2,3\n1.1,1,2,3\n1.05,1,2,3\n")
                .find(":4: column 'time': time does not increase"),
            std::string::npos);
  EXPECT_NE(klipper("same", std::string(kHeader) + "1.0,1,2,3\n1.0,1,2,3\n")
                .find(":3: column 'time': time does not increase"),
            std::string::npos);
  EXPECT_NE(klipper("fields", std::string(kHeader) + "1.0,1,2,3\n1.1,1,2\n")
                .find(":3: wrong number of fields (3, header has 4)"),
            std::string::npos);
  EXPECT_NE(klipper("blank", std::string(kHeader) + "1.0,1,2,3\n\n1.1,1,2,3\n").find(":3: blank line inside the data"),
            std::string::npos);
  EXPECT_NE(klipper("cut", std::string(kHeader) + "1.0,1,2,3\n1.1,1,2").find("truncated file"), std::string::npos);
  EXPECT_NE(error_of([] { read_klipper_capture("/nonexistent/raw.csv"); }).find("no such file"), std::string::npos);
  // A good one, CRLF line ends and a trailing blank line allowed; mm/s² to m/s².
  const std::string good = file_with("good", std::string("#time,accel_x,accel_y,accel_z\r\n") +
                                                 "10.000000,-1.5,2.25,9806.65\r\n10.000312,0,0,9806.65\r\n\n");
  const StampedAccel a = read_klipper_capture(good);
  ASSERT_EQ(a.t_s.size(), 2u);
  EXPECT_DOUBLE_EQ(a.accel_mps2[0].x(), -1.5e-3);
  EXPECT_DOUBLE_EQ(a.accel_mps2[0].z(), 9.80665);
}

TEST(ImportReaders, GenericCsvAndNcTracesNameWhatIsWrong) {
  CsvColumns named{"t", {"ax", "ay", "az"}, 1.0};
  const std::string missing = file_with("missing", "t,ax,ay\n0,1,2\n");
  EXPECT_NE(error_of([&] {
              read_accel_csv(missing, named, AccelUnit::g);
            }).find(":1: no column 'az' (the header has: t, ax, ay)"),
            std::string::npos);
  const std::string twice = file_with("twice", "t,ax,ay,az,ax\n0,1,2,3,4\n");
  EXPECT_NE(error_of([&] { read_accel_csv(twice, named, AccelUnit::g); }).find("column 'ax' appears twice"),
            std::string::npos);
  const std::string inf = file_with("inf", "t,ax,ay,az\n0,1,2,3\n0.001,1,inf,3\n");
  EXPECT_NE(error_of([&] { read_accel_csv(inf, named, AccelUnit::g); }).find(":3: column 'ay': NaN or Inf"),
            std::string::npos);
  const std::string ok = file_with("ok", "\"time\",\"z\",\"x\",\"y\"\n0.5,3,1,2\n0.6,3,1,2\n");
  const StampedAccel a = read_accel_csv(ok, {"time", {"x", "y", "z"}, 1.0}, AccelUnit::g);
  EXPECT_DOUBLE_EQ(a.accel_mps2[0].x(), kStandardGravity_mps2);
  EXPECT_DOUBLE_EQ(a.accel_mps2[0].z(), 3.0 * kStandardGravity_mps2);
  // halsampler: eight columns, increasing sample numbers, "overrun" lines pass.
  const std::string hal = file_with("hal", "100 1.0 2.0 3.0 1.0 2.0 3.0 0\noverrun\n105 1.5 2.0 3.0 1.5 2.0 3.0 0\n");
  const NcTrace t = read_halsampler(hal, 0.001);
  ASSERT_EQ(t.t_s.size(), 2u);
  EXPECT_DOUBLE_EQ(t.t_s[1], 0.105);
  const std::string short_line = file_with("halshort", "100 1.0 2.0\n");
  EXPECT_NE(error_of([&] { read_halsampler(short_line, 0.001); }).find(":1: column 4"), std::string::npos);
  const std::string back = file_with("halback", "100 1 2 3 1 2 3 0\n99 1 2 3 1 2 3 0\n");
  EXPECT_NE(error_of([&] { read_halsampler(back, 0.001); }).find(":2: sample number 99 does not increase"),
            std::string::npos);
  const std::string nc = file_with("nc", "t,x,y,z\n0,0,0,0\n0.001,0,0\n");
  EXPECT_NE(error_of([&] { read_nc_csv(nc, {}); }).find(":3: wrong number of fields"), std::string::npos);
}

TEST(ImportReaders, UniformClockFromMicrosecondStampsWithJitterAndAGap) {
  const double fs = 3187.3, jitter = 20e-6;
  std::mt19937_64 rng(11);
  std::normal_distribution<double> unit(0.0, 1.0);
  std::vector<double> t;
  for (int k = 0; k < 200000; ++k) {
    if (k >= 1000 && k < 1040) continue;  // 40 samples lost
    const double stamp = 1234.5 + k / fs + jitter * unit(rng);
    t.push_back(std::round(stamp * 1e6) / 1e6);  // Klipper prints %.6f
  }
  const UniformClock c = fit_uniform_clock(t, "stamps");
  std::printf(
      "stamps at 3187.3 Hz printed to 1 us with 20 us jitter: median dt %.1f us (fs %.2f Hz from it), fitted fs %.5f "
      "Hz, jitter %.2f us, "
      "%zu lost frames in %zu gaps\n",
      c.median_dt_s * 1e6, 1.0 / c.median_dt_s, c.fs_hz, c.jitter_rms_s * 1e6, c.lost_frames, c.gaps);
  EXPECT_NEAR(c.fs_hz, fs, 1e-3);
  EXPECT_EQ(c.lost_frames, 40u);
  EXPECT_EQ(c.gaps, 1u);
  EXPECT_NEAR(c.jitter_rms_s, std::sqrt(jitter * jitter + 1e-12 / 12.0), 0.5e-6);
  // Resampling: every kept sample's own grid point, none inside the gap.
  std::vector<Eigen::Vector3d> v(t.size(), Eigen::Vector3d(1.0, 2.0, 3.0));
  const UniformSeries s = resample(t, v, c);
  EXPECT_EQ(s.grid_index.size(), t.size());
  EXPECT_EQ(s.grid_index.back(), 199999);
  EXPECT_EQ(s.grid_index[1000] - s.grid_index[999], 41);
  EXPECT_NEAR((s.values[5000] - Eigen::Vector3d(1.0, 2.0, 3.0)).norm(), 0.0, 1e-12);  // a constant stays constant
  EXPECT_NE(error_of([] { fit_uniform_clock({0.0, 1.0, 2.0}, "three"); }).find("at least 4"), std::string::npos);
}

// A single lost sample leaves a stamp difference of 2·dt, which the jitter puts on either
// side of a 2·dt threshold: each one must count as a gap all the same (1.5·dt is the
// rounding boundary between one step and two), or every later sample sits one period
// early on the grid and the loss goes unflagged.
TEST(ImportReaders, UniformClockCountsEverySingleLostSample) {
  const double fs = 3187.3, jitter = 20e-6;
  std::mt19937_64 rng(12);
  std::normal_distribution<double> unit(0.0, 1.0);
  std::vector<double> t;
  std::size_t lost = 0;
  for (int k = 0; k < 100000; ++k) {
    if (k % 500 == 250) {  // one sample lost every 500
      ++lost;
      continue;
    }
    t.push_back(std::round((7.25 + k / fs + jitter * unit(rng)) * 1e6) / 1e6);
  }
  const UniformClock c = fit_uniform_clock(t, "stamps");
  std::printf(
      "%zu single samples lost at 3187.3 Hz, 20 us jitter: %zu lost frames in %zu gaps found, jitter %.2f us, fs %.4f "
      "Hz\n",
      lost, c.lost_frames, c.gaps, c.jitter_rms_s * 1e6, c.fs_hz);
  EXPECT_EQ(c.lost_frames, lost);
  EXPECT_EQ(c.gaps, lost);
  EXPECT_EQ(c.index.back(), 99999);
  EXPECT_NEAR(c.fs_hz, fs, 1e-2);
  EXPECT_LT(c.jitter_rms_s, 1.5 * jitter);
  // Exact stamps (halsampler's sample number × period): 2·dt is 2·median only to rounding.
  std::vector<double> exact;
  for (int n = 100; n < 5100; ++n)
    if (n % 97 != 0) exact.push_back(n * 0.001);
  const UniformClock e = fit_uniform_clock(exact, "halsampler");
  EXPECT_EQ(e.lost_frames, 51u);
  EXPECT_EQ(e.gaps, 51u);
}

}  // namespace
}  // namespace eical::drivers
