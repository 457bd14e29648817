// Fuzz target: a generic accelerometer CSV (eical import csv --accel A.csv) through
// drivers::read_accel_csv, then onto the importer's uniform clock. Byte 0 chooses the
// options the command line offers: columns by position or by name (t, ax, ay, az), the
// unit (mps2, mmps2, g) and the time unit (s, ms, us).
#include "drivers/import/capture_files.hpp"
#include "fuzz/import_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace eical;
  if (size < 1) return 0;
  drivers::CsvColumns columns;
  if (data[0] & 1) columns.time = "t", columns.values = {"ax", "ay", "az"};
  const drivers::AccelUnit units[3] = {drivers::AccelUnit::mps2, drivers::AccelUnit::mmps2, drivers::AccelUnit::g};
  const double time_units[3] = {1.0, 1e-3, 1e-6};
  const auto unit = units[(data[0] >> 1) % 3];
  columns.time_scale_s = time_units[(data[0] >> 3) % 3];
  const auto file = fuzz::write_input("accel.csv", fuzz::as_text(data + 1, size - 1));
  fuzz::expect_clean(file.string(), [&] {
    const auto c = drivers::read_accel_csv(file, columns, unit);
    fuzz::to_uniform_clock(c.t_s, c.accel_mps2, c.source);
  });
  return 0;
}
