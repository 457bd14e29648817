// Fuzz target: the points of eical volumetric --points P.csv (x,y,z,xp,yp,zp) through
// tools::read_volumetric_points_csv, each evaluated in the example model
// (config/examples/volumetric-example.toml) as the command does.
#include "dsp/comp/volumetric.hpp"
#include "fuzz/fuzz_support.hpp"
#include "tools/io/csv_inputs.hpp"
#include "tools/io/volumetric_model_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace eical;
  static const auto model = tools::read_volumetric_model(EICAL_SOURCE_DIR "/config/examples/volumetric-example.toml");
  const auto file = fuzz::write_input("points.csv", fuzz::as_text(data, size));
  fuzz::expect_clean(file.string(), [&] {
    for (const auto& p : tools::read_volumetric_points_csv(file.string())) {
      const auto d = dsp::comp::volumetric_deviation(model.model, p.x_mm, p.tool_mm);
      if (d.ok()) (void)dsp::comp::prediction_u_k2(model, p.x_mm);
    }
  });
  return 0;
}
