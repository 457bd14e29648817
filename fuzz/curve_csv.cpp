// Fuzz target: the error curve (eical lincomp --curve C.csv: pos_mm,error_um) through
// tools::read_error_curve_csv, then the piecewise-linear table at the command's default
// grid (50 mm spacing, 1 mm shift step), as eical lincomp computes it before writing.
#include "dsp/comp/lincomp.hpp"
#include "fuzz/fuzz_support.hpp"
#include "tools/io/csv_inputs.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace eical;
  const auto file = fuzz::write_input("curve.csv", fuzz::as_text(data, size));
  fuzz::expect_clean(file.string(), [&] {
    const auto curve = tools::read_error_curve_csv(file.string());
    try {
      (void)dsp::comp::piecewise_linear(curve, {50.0, 1.0, 0.0});
    } catch (const dsp::InputError&) {
      // lincomp's own checks name the curve's points, not the file (the command adds neither)
    }
  });
  return 0;
}
