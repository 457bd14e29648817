// Fuzz target: a recorded run directory (eical-run/1) through drivers::read_run.
// Input: run.toml text, then optionally "\n%%samples\n" and the samples file (gzip when it
// starts with the gzip magic, as samples.csv.gz), then optionally "\n%%truth\n" and
// truth.toml. The samples reader depends on run.toml (fs, ADC, [[psd]] count), so both
// parts come from one input.
#include "drivers/run_io/run_reader.hpp"
#include "fuzz/fuzz_support.hpp"

#include <cmath>

namespace {

constexpr std::string_view kSamples = "\n%%samples\n", kTruth = "\n%%truth\n";

std::string_view cut(std::string_view& rest, std::string_view marker) {
  const auto at = rest.find(marker);
  if (at == std::string_view::npos) {
    const std::string_view all = rest;
    rest = {};
    return all;
  }
  const std::string_view head = rest.substr(0, at);
  rest.remove_prefix(at + marker.size());
  return head;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace eical;
  namespace fs = std::filesystem;
  const fs::path dir = fuzz::scratch_dir() / "run";
  std::error_code ec;
  fs::remove_all(dir, ec);
  fs::create_directories(dir);
  std::string_view rest = fuzz::as_text(data, size);
  const bool has_samples = rest.find(kSamples) != std::string_view::npos;
  const std::string_view toml = cut(rest, kSamples);
  const bool has_truth = rest.find(kTruth) != std::string_view::npos;
  const std::string_view samples = cut(rest, kTruth);
  fuzz::write_input("run/run.toml", toml);
  if (has_samples) {
    const bool gz = samples.size() >= 2 && static_cast<unsigned char>(samples[0]) == 0x1f &&
                    static_cast<unsigned char>(samples[1]) == 0x8b;
    fuzz::write_input(gz ? "run/samples.csv.gz" : "run/samples.csv", samples);
  }
  if (has_truth) fuzz::write_input("run/truth.toml", rest);
  fuzz::expect_clean(dir.string(), [&] {
    const dsp::Run run = drivers::read_run(dir);
    // What the pipeline relies on from an accepted run.
    if (run.frames.empty()) fuzz::finding("a run without frames was accepted");
    if (!(run.meta.acquisition.fs_hz > 0.0) || !std::isfinite(run.meta.acquisition.fs_hz))
      fuzz::finding("fs_hz not positive and finite");
    for (std::size_t i = 1; i < run.frames.size(); ++i)
      if (run.frames[i].sample_index <= run.frames[i - 1].sample_index) fuzz::finding("sample index does not increase");
  });
  return 0;
}
