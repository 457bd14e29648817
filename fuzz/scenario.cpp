// Fuzz target: a simulation scenario (eical-scenario/1, config/scenarios/*.toml) through
// drivers::read_scenario_file.
#include "drivers/config/scenario_file.hpp"
#include "fuzz/fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace eical;
  const auto file = fuzz::write_input("scenario.toml", fuzz::as_text(data, size));
  fuzz::expect_clean(fuzz::scratch_dir().string(), [&] { (void)drivers::read_scenario_file(file.string()); });
  return 0;
}
