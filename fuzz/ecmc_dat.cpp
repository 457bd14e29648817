// Fuzz target: the ecmc ISO 230-2 data file (eical iso230-2 --ecmc F.dat: TGT_DATA[i],
// REF_DATA_FWD[i,j], REF_DATA_BWD[i,j]) through tools::read_ecmc_dat, then evaluated.
#include "dsp/eval/positioning.hpp"
#include "fuzz/fuzz_support.hpp"
#include "tools/io/positioning_readers.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace eical;
  const auto file = fuzz::write_input("iso230-2.dat", fuzz::as_text(data, size));
  fuzz::expect_clean(file.string(),
                     [&] { (void)dsp::eval::evaluate_positioning(tools::read_ecmc_dat(file.string())); });
  return 0;
}
