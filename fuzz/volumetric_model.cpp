// Fuzz target: the volumetric model file (eical-volumetric/1) through
// tools::read_volumetric_model, then evaluated at the corners and the centre of its range
// as eical volumetric --model does at the user's points.
#include "dsp/comp/volumetric.hpp"
#include "fuzz/fuzz_support.hpp"
#include "tools/io/volumetric_model_file.hpp"

#include <cmath>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace eical;
  const auto file = fuzz::write_input("volumetric.toml", fuzz::as_text(data, size));
  fuzz::expect_clean(file.string(), [&] {
    const auto fit = tools::read_volumetric_model(file.string());
    const auto& r = fit.model.range_mm;
    for (int corner = 0; corner < 9; ++corner) {
      Eigen::Vector3d x;
      for (int a = 0; a < 3; ++a) x[a] = corner == 8 ? 0.5 * (r[a][0] + r[a][1]) : r[a][(corner >> a) & 1];
      const auto d = dsp::comp::volumetric_deviation(fit.model, x, Eigen::Vector3d(0.0, 0.0, 100.0));
      if (d.ok() && !d.e_um.allFinite()) fuzz::finding("a deviation inside the model's range is not finite");
      (void)dsp::comp::prediction_u_k2(fit, x);
    }
  });
  return 0;
}
