// Inputs of the drivers' fuzz targets (fuzz/corpus/<target>/finding-* found by the fuzzer,
// review-* by reading the reader while writing its target), through the normal readers:
// the clean one-line error naming the file, nothing else.
#include "drivers/import/capture_files.hpp"
#include "drivers/import/shaketune_file.hpp"
#include "drivers/import/uniform_clock.hpp"
#include "drivers/run_io/run_reader.hpp"
#include "dsp/core/error.hpp"
#include "tests/support/temp_dir.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <random>

namespace {

namespace fs = std::filesystem;

std::string corpus(const std::string& target, const std::string& input) {
  const fs::path p = fs::path(EICAL_SOURCE_DIR) / "fuzz" / "corpus" / target / input;
  std::ifstream is(p, std::ios::binary);
  EXPECT_TRUE(is) << p;
  return {std::istreambuf_iterator<char>(is), std::istreambuf_iterator<char>()};
}

using test_support::TempDir;

// A run_dir input as fuzz/run_dir.cpp lays it out: run.toml, "\n%%samples\n", samples.csv.
fs::path run_dir_of(const std::string& input, const TempDir& tmp) {
  const std::string text = corpus("run_dir", input);
  const auto cut = text.find("\n%%samples\n");
  std::ofstream(tmp.path / "run.toml", std::ios::binary) << text.substr(0, cut);
  if (cut != std::string::npos) std::ofstream(tmp.path / "samples.csv", std::ios::binary) << text.substr(cut + 11);
  return tmp.path;
}

std::string error_of(const std::function<void()>& read) {
  try {
    read();
  } catch (const eical::dsp::InputError& e) {
    return e.what();
  }
  return "";
}

// adc_bits = 4294967312 (2^32 + 16) was narrowed to int, became 16 and was accepted: a
// config value that does not do what it says. Integers that must fit an int are refused
// beyond its range now (StrictTable::int32).
TEST(DriversFuzz, AdcBitsBeyondIntIsRefusedNotNarrowed) {
  TempDir tmp;
  const fs::path dir = run_dir_of("review-adc-bits-beyond-int", tmp);
  const std::string what = error_of([&] { (void)eical::drivers::read_run(dir); });
  EXPECT_NE(what.find((dir / "run.toml").string() + ":7: acquisition.adc_bits: integer 4294967312 is out of range"),
            std::string::npos)
      << what;
}

// A PSD current of 1e300 V became llround(1e300 / lsb): an unspecified value cut to 32 bits,
// recorded as a plausible count; a temperature of -1e300 C was converted to float
// (undefined beyond its range). Both are refused with the line and column now.
TEST(DriversFuzz, SampleValuesBeyondWhatTheDaqRecordsAreRefused) {
  TempDir tmp;
  std::string what = error_of([&] { (void)eical::drivers::read_run(run_dir_of("review-psd-beyond-adc", tmp)); });
  EXPECT_NE(what.find("samples.csv:3: column 'psd0_i1': PSD value beyond the ADC's 32-bit range ('1e300')"),
            std::string::npos)
      << what;
  TempDir tmp2;
  what = error_of([&] { (void)eical::drivers::read_run(run_dir_of("review-temperature-beyond-float", tmp2)); });
  EXPECT_NE(what.find("samples.csv:4: column 'table_temp': temperature beyond +-1000 C ('-1e300')"), std::string::npos)
      << what;
}

// An nc_csv input as fuzz/nc_csv.cpp reads it (byte 0: options; 1 = columns t, x, y, z by
// name, seconds), through the importer's path: the reader, the uniform clock, the bridged grid.
std::string nc_trace_error(const std::string& input, const TempDir& tmp) {
  const std::string text = corpus("nc_csv", input);
  const fs::path file = tmp.path / "trace.csv";
  std::ofstream(file, std::ios::binary) << text.substr(1);
  eical::drivers::CsvColumns columns;
  columns.time = "t", columns.values = {"x", "y", "z"};
  const std::string what = error_of([&] {
    const auto nc = eical::drivers::read_nc_csv(file, columns);
    const auto clock = eical::drivers::fit_uniform_clock(nc.t_s, nc.source);
    (void)eical::drivers::bridge_gaps(nc.t_s, nc.pos_mm, clock);
  });
  EXPECT_NE(what.find(file.string()), std::string::npos) << what;
  return what;
}

// Four samples 1 ms apart, then one 1e9 s later: the clock counted 1e12 lost samples and
// the importer asked for a grid of 1e12 set-points (ASan: allocation beyond its maximum).
TEST(DriversFuzz, NcTraceWithAGapOfAGigasecondIsRefused) {
  TempDir tmp;
  const std::string what = nc_trace_error("review-gap-1e9-s", tmp);
  EXPECT_NE(what.find("a gap of 999999999.997000 s after sample 4 loses more samples than the 5 recorded"),
            std::string::npos)
      << what;
}

// Two gaps of 5e18 samples each: the grid index overflowed int64 (UBSan: signed overflow).
TEST(DriversFuzz, GapsWhoseIndicesWouldOverflowAreRefused) {
  TempDir tmp;
  const std::string what = nc_trace_error("review-gaps-overflow-index", tmp);
  EXPECT_NE(what.find("loses more samples than the 7 recorded (time stamps in another unit?)"), std::string::npos)
      << what;
}

// A Shake&Tune line with 100.0e2500: nlohmann's parser throws out_of_range for a number no
// double holds, not parse_error, and the reader caught only the latter: std::terminate.
TEST(DriversFuzz, ShakeTuneNumberBeyondADoubleIsRefusedNamingTheLine) {
  TempDir tmp;
  const fs::path file = tmp.path / "capture.stdata";
  std::ofstream(file, std::ios::binary) << corpus("shaketune_stdata", "finding-number-out-of-range");
  const std::string what = error_of([&] { (void)eical::drivers::read_shaketune_stdata(file); });
  EXPECT_NE(what.find(file.string() + ":1: not JSON"), std::string::npos) << what;
}

}  // namespace
