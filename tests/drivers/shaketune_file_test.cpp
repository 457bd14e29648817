// Shake&Tune's .stdata on byte streams: written and read back, what a file may hold (one
// or several measurements, several zstd frames) and what it is refused for (not zstd, cut
// short, the early pickled form, a broken line, a sample out of order), each by its cause.
#include "drivers/import/shaketune_file.hpp"
#include "dsp/core/error.hpp"
#include "tests/support/temp_dir.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <fstream>
#include <string>

namespace eical {
namespace {

namespace fs = std::filesystem;
using test_support::TempDir;

drivers::ShakeTuneMeasurement measurement(const std::string& name, int n, double t0) {
  drivers::ShakeTuneMeasurement m;
  m.name = name;
  for (int i = 0; i < n; ++i) {
    m.capture.t_s.push_back(t0 + i / 3200.0);
    m.capture.accel_mps2.emplace_back(0.001 * i, -0.5, 9.80665 + 1e-4 * i);
  }
  return m;
}

// One zstd frame holding `bytes` as a raw (stored) block: RFC 8878, 3.1.1 — magic, a
// single-segment header with a one-byte content size, one last raw block.
std::string zstd_raw_frame(const std::string& bytes) {
  EXPECT_LT(bytes.size(), 256U);
  std::string f = {'\x28', '\xB5', '\x2F', '\xFD', '\x20', static_cast<char>(bytes.size())};
  const std::uint32_t block = 1U | (0U << 1) | (static_cast<std::uint32_t>(bytes.size()) << 3);
  f += static_cast<char>(block & 0xFF), f += static_cast<char>((block >> 8) & 0xFF),
      f += static_cast<char>((block >> 16) & 0xFF);
  return f + bytes;
}

void write_bytes(const fs::path& file, const std::string& bytes) { std::ofstream(file, std::ios::binary) << bytes; }

std::string refusal(const fs::path& file) {
  try {
    (void)drivers::read_shaketune_stdata(file);
  } catch (const dsp::InputError& e) {
    return e.what();
  }
  return "";
}

TEST(ShakeTuneFile, WrittenAndReadBackSampleForSample) {
  const TempDir dir;
  const fs::path file = dir.path / "belts.stdata";
  drivers::write_shaketune_stdata(file, {measurement("belt_a_20241110", 500, 12.5), measurement("belt_b", 300, 90.0)});
  const auto back = drivers::read_shaketune_stdata(file);
  ASSERT_EQ(back.size(), 2U);
  EXPECT_EQ(back[0].name, "belt_a_20241110");
  EXPECT_EQ(back[1].capture.source, file.string() + "#belt_b");
  ASSERT_EQ(back[0].capture.t_s.size(), 500U);
  const auto ref = measurement("x", 500, 12.5);
  for (std::size_t i = 0; i < 500; i += 37) {
    EXPECT_DOUBLE_EQ(back[0].capture.t_s[i], ref.capture.t_s[i]);
    EXPECT_NEAR((back[0].capture.accel_mps2[i] - ref.capture.accel_mps2[i]).norm(), 0.0, 1e-12);  // mm/s2 and back
  }
}

TEST(ShakeTuneFile, AMeasurementIsPickedByNameOrRefusedListingThoseThere) {
  const std::vector<drivers::ShakeTuneMeasurement> two = {measurement("axis_x", 10, 0.0),
                                                          measurement("axis_y", 20, 5.0)};
  EXPECT_EQ(drivers::pick_measurement(two, "axis_y", "f").name, "axis_y");
  EXPECT_EQ(drivers::pick_measurement({two[0]}, "", "f").name, "axis_x");
  try {
    (void)drivers::pick_measurement(two, "", "f.stdata");
    FAIL() << "two measurements and no name";
  } catch (const dsp::InputError& e) {
    const std::string w = e.what();
    EXPECT_NE(w.find("--measurement"), std::string::npos) << w;
    EXPECT_NE(w.find("axis_x (10 samples"), std::string::npos) << w;
    EXPECT_NE(w.find("axis_y (20 samples"), std::string::npos) << w;
  }
  EXPECT_THROW((void)drivers::pick_measurement(two, "axis_z", "f"), dsp::InputError);
}

TEST(ShakeTuneFile, SeveralFramesAreOneStream) {
  const TempDir dir;
  const fs::path file = dir.path / "frames.stdata";
  write_bytes(file, zstd_raw_frame("{\"name\": \"a\", \"samples\": [[1.0, 0, 0, 9806.65]]}\n") +
                        zstd_raw_frame("{\"name\": \"b\", \"samples\": [[2.0, 1, 2, 3], [2.1, 4, 5, 6]]}\n"));
  const auto back = drivers::read_shaketune_stdata(file);
  ASSERT_EQ(back.size(), 2U);
  EXPECT_NEAR(back[0].capture.accel_mps2[0].z(), 9.80665, 1e-12);
  EXPECT_EQ(back[1].capture.t_s.size(), 2U);
}

TEST(ShakeTuneFile, EachBadFileIsRefusedByItsCause) {
  const TempDir dir;
  const fs::path f = dir.path / "bad.stdata";
  write_bytes(f, "#time,accel_x,accel_y,accel_z\n1,2,3,4\n");
  EXPECT_NE(refusal(f).find("not a Shake&Tune .stdata file"), std::string::npos) << refusal(f);

  const std::string good = zstd_raw_frame("{\"name\": \"a\", \"samples\": [[1.0, 0, 0, 1]]}\n");
  write_bytes(f, good.substr(0, good.size() - 5));
  EXPECT_NE(refusal(f).find("truncated"), std::string::npos) << refusal(f);

  write_bytes(f, zstd_raw_frame(std::string("\x80\x04\x95", 3) + "pickled list"));
  EXPECT_NE(refusal(f).find("Python pickle"), std::string::npos) << refusal(f);

  write_bytes(f, zstd_raw_frame("{\"name\": \"a\", \"samples\": [[1.0, 0, 0, 1]]}\n{\"name\": \"b\", \"samp"));
  EXPECT_NE(refusal(f).find("bad.stdata:2: not JSON"), std::string::npos) << refusal(f);

  // A number no double holds is nlohmann's out_of_range, not a parse_error (found by the fuzzer).
  write_bytes(f, zstd_raw_frame("{\"name\": \"a\", \"samples\": [[100.0e2500, 0, 0, 1]]}\n"));
  EXPECT_NE(refusal(f).find("bad.stdata:1: not JSON"), std::string::npos) << refusal(f);

  write_bytes(f, zstd_raw_frame("{\"name\": \"a\", \"samples\": [[1.0, 0, 0, 1], [0.5, 0, 0, 1]]}\n"));
  EXPECT_NE(refusal(f).find("measurement 'a', sample 1: time"), std::string::npos) << refusal(f);

  write_bytes(f, zstd_raw_frame("{\"name\": \"a\", \"samples\": [[1.0, 0, 1]]}\n"));
  EXPECT_NE(refusal(f).find("a sample is [time s"), std::string::npos) << refusal(f);

  write_bytes(f, zstd_raw_frame("\n\n"));
  EXPECT_NE(refusal(f).find("holds no measurement"), std::string::npos) << refusal(f);
}

}  // namespace
}  // namespace eical
