#include "drivers/run_io/run_reader.hpp"
#include "drivers/run_io/run_writer.hpp"
#include "dsp/core/error.hpp"
#include "dsp/core/frame_fields.hpp"
#include "tests/support/sample_data.hpp"
#include "tests/support/temp_dir.hpp"

#include <gtest/gtest.h>
#include <zlib.h>

#include <unistd.h>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>

namespace eical::drivers {
namespace {

namespace fs = std::filesystem;

using test_support::TempDir;

dsp::Run small_run() {
  dsp::Run r;
  r.meta.id = "unit-0001";
  r.meta.created = "2026-11-22T10:00:00Z";
  r.meta.program.kind = eical::dsp::ProgramKind::circle;
  r.meta.program.gcode = "G90\nM101\n";
  r.meta.psd = {dsp::PsdSpec{}, dsp::PsdSpec{}};
  r.meta.psd[1].measures = "y";
  r.meta.psd[1].center_mm[0] = 10.0;
  r.meta.reference = dsp::Reference{"KGM182", {"x", "y"}};
  r.meta.sensors[1].to_machine(0, 1) = 2.5e-4;
  r.channels.ref[0] = r.channels.ref[1] = true;
  r.channels.psd_count = 2;
  for (int i = 0; i < 300; ++i) {
    dsp::Frame f;
    f.sample_index = i < 150 ? i : i + 3;  // 3 lost frames
    if (i == 150) f.flags |= dsp::frame_flag::gap_before;
    for (int c = 0; c < 6; ++c) f.accel_counts[c] = 1000 * c - 7 * i + (c == 5 ? 1018000 : 0);
    for (int c = 0; c < 4; ++c) f.psd_counts[c] = -i + 13 * c;
    f.temp_c[0] = 21.5f, f.temp_c[1] = 22.25f;
    f.cmd_mm[0] = 7.0710678118654755 + i * 1e-3, f.cmd_mm[1] = -1.0 / 3.0, f.cmd_mm[2] = 0.0;
    f.ref_mm[0] = f.cmd_mm[0] + 1e-6, f.ref_mm[1] = i == 10 ? std::nan("") : f.cmd_mm[1];
    f.trigger = i == 20 ? 101 : i == 280 ? 103 : 0;
    // The reader names the empty fields too (frame_fields.hpp).
    if (i == 30)
      f.flags |= dsp::frame_flag::accel_missing | dsp::frame_flag::table_missing | dsp::frame_flag::head_missing |
                 dsp::frame_flag::sensor_fields_missing(0) | dsp::frame_flag::sensor_fields_missing(1),
          std::fill(std::begin(f.accel_counts), std::end(f.accel_counts), 0);
    if (i == 31)
      f.flags |=
          dsp::frame_flag::accel_missing | dsp::frame_flag::head_missing | dsp::frame_flag::sensor_fields_missing(1),
          std::fill(std::begin(f.accel_counts) + 3, std::end(f.accel_counts), 0);
    r.frames.push_back(f);
  }
  r.truth_toml = "generator = \"unit\"\n";
  return r;
}

void expect_same(const dsp::Run& a, const dsp::Run& b) {
  EXPECT_EQ(a.meta.id, b.meta.id);
  EXPECT_EQ(a.meta.program.gcode, b.meta.program.gcode);
  EXPECT_EQ(a.meta.psd.size(), b.meta.psd.size());
  EXPECT_EQ(a.meta.sensors[1].to_machine, b.meta.sensors[1].to_machine);
  EXPECT_EQ(a.meta.sensors[0].k1_v_per_g, b.meta.sensors[0].k1_v_per_g);
  EXPECT_EQ(a.truth_toml, b.truth_toml);
  ASSERT_EQ(a.frames.size(), b.frames.size());
  for (std::size_t i = 0; i < a.frames.size(); ++i) {
    const auto &x = a.frames[i], &y = b.frames[i];
    ASSERT_EQ(x.sample_index, y.sample_index) << i;
    ASSERT_EQ(x.flags, y.flags) << i;
    ASSERT_EQ(x.psd_missing_electrodes, y.psd_missing_electrodes) << i;
    for (int c = 0; c < 6; ++c) ASSERT_EQ(x.accel_counts[c], y.accel_counts[c]) << i;
    for (int c = 0; c < 2 * a.channels.psd_count; ++c) ASSERT_EQ(x.psd_counts[c], y.psd_counts[c]) << i;
    for (int k = 0; k < 3; ++k) {
      ASSERT_EQ(x.cmd_mm[k], y.cmd_mm[k]) << i;
      ASSERT_TRUE(x.ref_mm[k] == y.ref_mm[k] || (std::isnan(x.ref_mm[k]) && std::isnan(y.ref_mm[k]))) << i;
    }
    ASSERT_EQ(x.temp_c[0], y.temp_c[0]);
    ASSERT_EQ(x.trigger, y.trigger);
  }
}

TEST(RunIo, RoundTripPlainAndGzip) {
  TempDir tmp;
  const dsp::Run run = small_run();
  for (bool gz : {false, true}) {
    const fs::path dir = tmp.path / (gz ? "gz" : "plain");
    write_run(run, dir, {.gzip = gz});
    EXPECT_TRUE(fs::exists(dir / (gz ? "samples.csv.gz" : "samples.csv")));
    expect_same(run, read_run(dir));
  }
}

// 16 strips, the most a frame holds: every electrode's column written and read back, and
// an empty electrode named as that one (the others of that sample kept).
TEST(RunIo, SixteenStripsRoundTripWithOneEmptyElectrode) {
  TempDir tmp;
  dsp::Run run = small_run();
  run.meta.psd.assign(dsp::kMaxPsd, dsp::PsdSpec{});
  for (int k = 0; k < dsp::kMaxPsd; ++k) run.meta.psd[static_cast<std::size_t>(k)].center_mm[0] = 5.0 * k;
  run.channels.psd_count = dsp::kMaxPsd;
  for (auto& f : run.frames)
    for (int c = 0; c < 2 * dsp::kMaxPsd; ++c) f.psd_counts[c] = static_cast<std::int32_t>(100 * c - f.sample_index);
  dsp::frame_flag::mark_psd_field_missing(run.frames[40], 27);  // strip 13's i2
  run.frames[40].psd_counts[27] = 0;
  write_run(run, tmp.path / "r");
  const dsp::Run back = read_run(tmp.path / "r");
  ASSERT_EQ(back.channels.psd_count, dsp::kMaxPsd);
  expect_same(run, back);
  EXPECT_EQ(back.frames[40].psd_missing_electrodes, 1u << 27);
  EXPECT_EQ(back.frames[40].psd_counts[26], 100 * 26 - back.frames[40].sample_index);
}

// run-format.md, "One sensor": a triplex empty in every row is absent, not missing — the
// other sensor's samples stay good and nothing is flagged.
TEST(RunIo, SingleSensorRunKeepsTheOtherSensorsData) {
  TempDir tmp;
  dsp::Run run = small_run();
  run.meta.sensor_present[0] = false;
  for (auto& f : run.frames)
    f.flags &= ~(dsp::frame_flag::table_missing | dsp::frame_flag::head_missing | dsp::frame_flag::accel_missing |
                 dsp::frame_flag::sensor_fields_missing(0) | dsp::frame_flag::sensor_fields_missing(1));
  write_run(run, tmp.path / "one", {});
  const dsp::Run back = read_run(tmp.path / "one");
  EXPECT_FALSE(back.meta.sensor_present[0]);
  EXPECT_TRUE(back.meta.sensor_present[1]);
  for (std::size_t i = 0; i < back.frames.size(); ++i) {
    ASSERT_EQ(back.frames[i].flags &
                  (dsp::frame_flag::accel_missing | dsp::frame_flag::table_missing | dsp::frame_flag::head_missing),
              0u)
        << i;
    for (int c = 3; c < 6; ++c) ASSERT_EQ(back.frames[i].accel_counts[c], run.frames[i].accel_counts[c]) << i;
  }
  // Both triplexes empty: no accelerometer at all is an error naming the cause.
  run.meta.sensor_present[1] = false;
  write_run(run, tmp.path / "none", {});
  try {
    (void)read_run(tmp.path / "none");
    FAIL() << "a run without accelerometer data was accepted";
  } catch (const dsp::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("no accelerometer data"), std::string::npos) << e.what();
  }
}

TEST(RunIo, ReadsEverySharedRun) {
  int runs = 0;
  for (const fs::path& dir : test::all_runs()) {
    const dsp::Run r = read_run(dir);
    ++runs;
    EXPECT_GT(r.frames.size(), 1000u) << dir;
    EXPECT_EQ(r.channels.psd_count, static_cast<int>(r.meta.psd.size()));
    EXPECT_TRUE(r.truth_toml.has_value()) << dir;
    for (std::size_t i = 0; i < r.frames.size(); ++i) {
      ASSERT_EQ(r.frames[i].sample_index, static_cast<std::int64_t>(i)) << dir;
      ASSERT_TRUE(std::isfinite(r.frames[i].cmd_mm[0]));
    }
  }
  EXPECT_GT(runs, 0);
}

// A valid run on disk that the bad-input tests then break one way each.
struct Fixture {
  TempDir tmp;
  fs::path dir;
  Fixture() : dir(tmp.path / "run") { write_run(small_run(), dir); }
  std::string read(const char* f) {
    std::ifstream is(dir / f);
    return {std::istreambuf_iterator<char>(is), std::istreambuf_iterator<char>()};
  }
  void write(const char* f, const std::string& s) { std::ofstream(dir / f, std::ios::trunc) << s; }
  void replace(const char* f, const std::string& from, const std::string& to) {
    std::string s = read(f);
    const auto p = s.find(from);
    ASSERT_NE(p, std::string::npos) << from;
    s.replace(p, from.size(), to);
    write(f, s);
  }
  std::string error() {
    try {
      (void)read_run(dir);
    } catch (const dsp::InputError& e) {
      return e.what();
    }
    return "";
  }
};

void expect_error(const std::string& msg, std::initializer_list<const char*> parts) {
  ASSERT_FALSE(msg.empty()) << "accepted";
  for (const char* p : parts) EXPECT_NE(msg.find(p), std::string::npos) << "'" << p << "' not in: " << msg;
}

TEST(RunIoBadInput, MalformedToml) {
  Fixture f;
  f.replace("run.toml", "fs_hz = 10000.0", "fs_hz = = 1");
  expect_error(f.error(), {"run.toml:", ":"});
}
TEST(RunIoBadInput, WrongTypeForAKey) {
  Fixture f;
  f.replace("run.toml", "fs_hz = 10000.0", "fs_hz = \"fast\"");
  expect_error(f.error(), {"run.toml:", "acquisition.fs_hz", "expected a number, got string"});
}
TEST(RunIoBadInput, MissingRequiredKey) {
  Fixture f;
  f.replace("run.toml", "id = \"unit-0001\"\n", "");
  expect_error(f.error(), {"run.toml", "id", "required key is missing"});
}
TEST(RunIoBadInput, MissingColumn) {
  Fixture f;
  f.replace("samples.csv", "head_ay,", "head_ay_renamed,");
  expect_error(f.error(), {"samples.csv:1:", "'head_ay'", "missing"});
}
TEST(RunIoBadInput, NonIntegerCounts) {
  Fixture f;
  std::string s = f.read("samples.csv");
  const auto line3 = s.find('\n', s.find('\n', s.find('\n') + 1) + 1) + 1;  // start of line 4
  const auto comma = s.find(',', line3);
  const auto comma2 = s.find(',', comma + 1);
  s.replace(comma + 1, comma2 - comma - 1, "12.5");
  f.write("samples.csv", s);
  expect_error(f.error(), {"samples.csv:4:", "'table_ax'", "integer ADC counts", "12.5"});
}
TEST(RunIoBadInput, NaNInASample) {
  Fixture f;
  f.replace("samples.csv", ",21.5,", ",nan,");
  expect_error(f.error(), {"samples.csv:2:", "'table_temp'", "NaN"});
}
TEST(RunIoBadInput, WrongFieldCount) {
  Fixture f;
  std::string s = f.read("samples.csv");
  const auto l2 = s.find('\n') + 1;
  s.insert(s.find('\n', l2), ",1");
  f.write("samples.csv", s);
  expect_error(f.error(), {"samples.csv:2:", "wrong number of fields"});
}
TEST(RunIoBadInput, TruncatedPlainFile) {
  Fixture f;
  std::string s = f.read("samples.csv");
  s.resize(s.size() - 20);
  f.write("samples.csv", s);
  expect_error(f.error(), {"samples.csv:", "truncated"});
}
TEST(RunIoBadInput, TruncatedGzip) {
  Fixture f;
  const std::string s = f.read("samples.csv");
  fs::remove(f.dir / "samples.csv");
  const std::string gz = (f.dir / "samples.csv.gz").string();
  gzFile g = gzopen(gz.c_str(), "wb");
  gzwrite(g, s.data(), static_cast<unsigned>(s.size()));
  gzclose(g);
  fs::resize_file(gz, fs::file_size(gz) / 2);
  expect_error(f.error(), {"samples.csv.gz", "truncated"});
}
TEST(RunIoBadInput, TimeNotIncreasing) {
  Fixture f;
  f.replace("samples.csv", "\n0.0002,", "\n0.0001,");
  expect_error(f.error(), {"samples.csv:4:", "'t'", "does not increase"});
}
TEST(RunIoBadInput, NoSamplesFile) {
  Fixture f;
  fs::remove(f.dir / "samples.csv");
  expect_error(f.error(), {"no samples.csv"});
}
TEST(RunIoBadInput, PsdColumnsMustMatchPsdTables) {
  Fixture f;
  f.replace("samples.csv", "psd1_i1,", "psdX_i1,");
  expect_error(f.error(), {"'psd1_i1'", "[[psd]]"});
}

TEST(RunIoWriter, UnwritablePlaceFailsWithThePathAndLeavesNothing) {
  TempDir tmp;
  // A parent that is a regular file cannot hold a run, not even for root.
  const fs::path file = tmp.path / "not-a-dir";
  std::ofstream(file) << "x";
  try {
    write_run(small_run(), file / "run");
    FAIL() << "wrote below a regular file";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(file.string()), std::string::npos) << e.what();
  }
  write_run(small_run(), tmp.path / "new" / "parents" / "run");  // missing parents are created
  EXPECT_EQ(read_run(tmp.path / "new" / "parents" / "run").meta.id, "unit-0001");
  if (::geteuid() != 0) {  // permissions bind everyone but root
    const fs::path ro = tmp.path / "ro";
    fs::create_directories(ro);
    fs::permissions(ro, fs::perms::owner_read | fs::perms::owner_exec);
    EXPECT_THROW(write_run(small_run(), ro / "run"), std::runtime_error);
    fs::permissions(ro, fs::perms::owner_all);
    EXPECT_TRUE(fs::is_empty(ro)) << "a temporary directory was left behind";
  }
  int entries = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(tmp.path)) ++entries;
  EXPECT_EQ(entries, ::geteuid() != 0 ? 3 : 2);  // the file, "new" and (non-root) "ro"
}

TEST(RunIoWriter, ExistingRunIsNeverCorrupted) {
  TempDir tmp;
  const fs::path dir = tmp.path / "run";
  dsp::Run first = small_run();
  write_run(first, dir);
  dsp::Run second = small_run();
  second.meta.id = "unit-0002";
  EXPECT_THROW(write_run(second, dir), std::runtime_error);  // overwrite = false
  EXPECT_EQ(read_run(dir).meta.id, "unit-0001");
  write_run(second, dir, {.overwrite = true});
  EXPECT_EQ(read_run(dir).meta.id, "unit-0002");
  int entries = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(tmp.path)) ++entries;
  EXPECT_EQ(entries, 1) << "temporary or old directories left behind";
}

}  // namespace
}  // namespace eical::drivers
