// Fuzz target: a sensor calibration (eical-sensor-cal/1) through
// drivers::read_sensor_calibration, then applied to a run's metadata as eical analyze
// --calibration and eicald do.
#include "drivers/config/sensor_calibration.hpp"
#include "fuzz/fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace eical;
  const auto file = fuzz::write_input("sensor-cal.toml", fuzz::as_text(data, size));
  fuzz::expect_clean(file.string(), [&] {
    dsp::RunMeta meta;  // the data sheet the calibration overrides
    const auto cal = drivers::read_sensor_calibration(file, meta);
    drivers::apply_calibration(cal, meta);
  });
  return 0;
}
