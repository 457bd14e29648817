// Fuzz target: the interleaved angle series (eical fourier --series S.csv:
// angle_deg,deviation_arcsec,series) through tools::read_angle_series_csv, then the Fourier
// calibration function with the command's defaults.
#include "dsp/comp/fourier.hpp"
#include "fuzz/fuzz_support.hpp"
#include "tools/io/csv_inputs.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace eical;
  const auto file = fuzz::write_input("series.csv", fuzz::as_text(data, size));
  fuzz::expect_clean(file.string(), [&] {
    const auto series = tools::read_angle_series_csv(file.string());
    try {
      (void)dsp::comp::fourier_calibration(series, {});
    } catch (const dsp::InputError&) {
      // the calibration's own checks name the series, not the file
    }
  });
  return 0;
}
