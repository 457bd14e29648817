// Fuzz target: a servo-trace CSV (eical import csv --nc TRACE --nc-format csv) through
// drivers::read_nc_csv, then onto the importer's uniform clock. Byte 0: columns by
// position or by name (t, x, y, z), and the time unit (s, ms, us).
#include "drivers/import/capture_files.hpp"
#include "fuzz/import_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace eical;
  if (size < 1) return 0;
  drivers::CsvColumns columns;
  if (data[0] & 1) columns.time = "t", columns.values = {"x", "y", "z"};
  const double time_units[3] = {1.0, 1e-3, 1e-6};
  columns.time_scale_s = time_units[(data[0] >> 1) % 3];
  const auto file = fuzz::write_input("trace.csv", fuzz::as_text(data + 1, size - 1));
  fuzz::expect_clean(file.string(), [&] {
    const auto nc = drivers::read_nc_csv(file, columns);
    fuzz::to_uniform_clock(nc.t_s, nc.pos_mm, nc.source, true);
  });
  return 0;
}
