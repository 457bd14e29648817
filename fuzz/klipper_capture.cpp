// Fuzz target: a Klipper raw accelerometer capture (eical import klipper CAPTURE) through
// drivers::read_klipper_capture, then onto the importer's uniform clock.
#include "drivers/import/capture_files.hpp"
#include "fuzz/import_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace eical;
  const auto file = fuzz::write_input("raw_data.csv", fuzz::as_text(data, size));
  fuzz::expect_clean(file.string(), [&] {
    const auto c = drivers::read_klipper_capture(file);
    fuzz::to_uniform_clock(c.t_s, c.accel_mps2, c.source);
  });
  return 0;
}
