// Fuzz target: Shake&Tune's .stdata (eical import shaketune FILE) through
// drivers::read_shaketune_stdata — the zstd stream, then the JSON lines — and each
// measurement onto the importer's uniform clock.
#include "drivers/import/shaketune_file.hpp"
#include "fuzz/import_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace eical;
  const auto file = fuzz::write_input("measurements.stdata", fuzz::as_text(data, size));
  fuzz::expect_clean(file.string(), [&] {
    for (const auto& m : drivers::read_shaketune_stdata(file)) {
      if (m.capture.t_s.size() != m.capture.accel_mps2.size()) fuzz::finding("stamps and values of unequal length");
      if (m.capture.t_s.size() >= 2) fuzz::to_uniform_clock(m.capture.t_s, m.capture.accel_mps2, m.capture.source);
    }
  });
  return 0;
}
