// Inputs of the drivers' fuzz targets (fuzz/corpus/<target>/finding-* found by the fuzzer,
// review-* by reading the reader while writing its target), through the normal readers:
// the clean one-line error naming the file, nothing else.
#include "drivers/run_io/run_reader.hpp"
#include "dsp/core/error.hpp"

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

struct TempDir {
  fs::path path = fs::temp_directory_path() / ("eical-finding-" + std::to_string(std::random_device{}()));
  TempDir() { fs::create_directories(path); }
  ~TempDir() { fs::remove_all(path); }
};

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
  EXPECT_NE(what.find((dir / "run.toml").string() + ":7: acquisition.adc_bits: integer 4294967312 is out of range"), std::string::npos) << what;
}

}  // namespace
