// Fuzz target: the ISO 230-2 deviation table (eical iso230-2 --deviations D.csv) through
// tools::read_deviation_csv, then evaluated as the command does.
#include "dsp/eval/positioning.hpp"
#include "fuzz/fuzz_support.hpp"
#include "tools/io/positioning_readers.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace eical;
  const auto file = fuzz::write_input("deviations.csv", fuzz::as_text(data, size));
  fuzz::expect_clean(file.string(),
                     [&] { (void)dsp::eval::evaluate_positioning(tools::read_deviation_csv(file.string())); });
  return 0;
}
