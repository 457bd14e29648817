// The inputs the fuzz targets found (fuzz/corpus/<target>/finding-*), each through the
// normal reader as eical reads it: the clean one-line error naming the file, nothing else.
#include "dsp/core/error.hpp"
#include "tools/io/csv_inputs.hpp"
#include "tools/io/positioning_readers.hpp"
#include "tools/io/volumetric_model_file.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <random>

namespace {

namespace fs = std::filesystem;

// The corpus file copied to a fresh temporary file; `read` must throw an InputError that
// names that file and says `says`. Returns the message.
std::string error_of(const std::string& target, const std::string& finding,
                     const std::function<void(const std::string&)>& read) {
  const fs::path src = fs::path(EICAL_SOURCE_DIR) / "fuzz" / "corpus" / target / finding;
  EXPECT_TRUE(fs::exists(src)) << src;
  const fs::path file =
      fs::temp_directory_path() / ("eical-finding-" + std::to_string(std::random_device{}()) + "-" + finding);
  fs::copy_file(src, file, fs::copy_options::overwrite_existing);
  std::string what;
  try {
    read(file.string());
  } catch (const eical::dsp::InputError& e) {
    what = e.what();
  }
  fs::remove(file);
  EXPECT_NE(what.find(file.string()), std::string::npos) << "does not name the file: " << what;
  EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  return what;
}

void expect_says(const std::string& what, const std::string& says) {
  EXPECT_NE(what.find(says), std::string::npos) << what;
}

// ISO 230-2 tables too small for the evaluation: evaluate_positioning refused them without
// naming the file; the readers check it now.
TEST(FuzzFindings, DeviationCsvWithOneTargetNamesTheFile) {
  expect_says(error_of("deviation_csv", "finding-one-target",
                       [](const std::string& f) { (void)eical::tools::read_deviation_csv(f); }),
              "at least 2 targets are needed for ISO 230-2 (the file has 1)");
}

TEST(FuzzFindings, EcmcDatWithoutCyclesNamesTheFile) {
  expect_says(
      error_of("ecmc_dat", "finding-no-cycles", [](const std::string& f) { (void)eical::tools::read_ecmc_dat(f); }),
      "at least 2 cycles per direction are needed for ISO 230-2 (the file has 0)");
}

// A run (cycle) number far beyond the rows: the reader allocated a row for every run up to
// it before finding the first missing one (ASan: allocation of 2.4e13 bytes; 48 GB for
// the ecmc cycle). Runs are added as they are complete now.
TEST(FuzzFindings, RunNumberFarBeyondTheRowsEndsAtTheFirstMissingRun) {
  expect_says(error_of("deviation_csv", "review-run-1e12",
                       [](const std::string& f) { (void)eical::tools::read_deviation_csv(f); }),
              "no deviation for target 0.000000 mm, run 2, up");
  expect_says(
      error_of("ecmc_dat", "review-cycle-2e9", [](const std::string& f) { (void)eical::tools::read_ecmc_dat(f); }),
      "REF_DATA_FWD[1,1] is missing");
}

// A component with more positions than values: the model's validation refused it without
// naming the file; the reader checks the count with the line now.
TEST(FuzzFindings, VolumetricModelValuesCountNamesFileAndLine) {
  const std::string what = error_of("volumetric_model", "finding-values-count",
                                    [](const std::string& f) { (void)eical::tools::read_volumetric_model(f); });
  expect_says(what, ":23: component[1].values: expected 12 numbers, got 9");
}

// A curve whose positions reach 5.6e13 mm: at 50 mm spacing lincomp built a table of 1e12
// points (timeout). Refused now, promptly, with the figure (the travel bound comes first).
TEST(FuzzFindings, CurveWithAnImpossibleTravelIsRefused) {
  const fs::path file = fs::path(EICAL_SOURCE_DIR) / "fuzz" / "corpus" / "curve_csv" / "finding-huge-travel";
  const auto curve = eical::tools::read_error_curve_csv(file.string());
  ASSERT_EQ(curve.pos_mm.size(), 2u);  // 49 mm and 5.6e13 mm
  std::string what;
  try {
    (void)eical::dsp::comp::piecewise_linear(curve, {50.0, 1.0, 0.0});
  } catch (const eical::dsp::InputError& e) {
    what = e.what();
  }
  expect_says(what, "more than the 100 m of any machine axis (positions in mm?)");
  try {
    what.clear();
    (void)eical::dsp::comp::piecewise_linear({{0.0, 100.0}, {0.0, 1.0}}, {10.0, 1e-4, 0.0});
  } catch (const eical::dsp::InputError& e) {
    what = e.what();
  }
  expect_says(what, "is more than 10000 grid shifts");
}

}  // namespace
