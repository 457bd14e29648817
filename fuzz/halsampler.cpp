// Fuzz target: a LinuxCNC halsampler NC trace (eical import csv --nc TRACE
// --nc-format halsampler) through drivers::read_halsampler at a 1 ms servo period, then
// onto the importer's uniform clock with its gaps bridged.
#include "drivers/import/capture_files.hpp"
#include "fuzz/import_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace eical;
  const auto file = fuzz::write_input("trace.hal", fuzz::as_text(data, size));
  fuzz::expect_clean(file.string(), [&] {
    const auto nc = drivers::read_halsampler(file, 0.001);
    fuzz::to_uniform_clock(nc.t_s, nc.pos_mm, nc.source, true);
  });
  return 0;
}
