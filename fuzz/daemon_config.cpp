// Fuzz target: eicald's configuration (config/eicald.toml) through daemon::load_daemon_config.
#include "daemon/config/daemon_config.hpp"
#include "fuzz/fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace eical;
  const auto file = fuzz::write_input("eicald.toml", fuzz::as_text(data, size));
  // Errors name eicald.toml, or a file it refers to (program_file): both are in the scratch directory.
  fuzz::expect_clean(fuzz::scratch_dir().string(), [&] { (void)daemon::load_daemon_config(file); });
  return 0;
}
