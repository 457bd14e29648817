// Inputs of the daemon config's fuzz target (fuzz/corpus/daemon_config/finding-* found by
// the fuzzer, review-* by reading the reader while writing it), through the normal reader:
// the clean one-line error naming the file, nothing else.
#include "daemon/config/daemon_config.hpp"
#include "dsp/core/error.hpp"

#include <gtest/gtest.h>

#include <filesystem>

namespace {

namespace fs = std::filesystem;

std::string finding_error(const std::string& input) {
  const fs::path file = fs::path(EICAL_SOURCE_DIR) / "fuzz" / "corpus" / "daemon_config" / input;
  EXPECT_TRUE(fs::exists(file)) << file;
  std::string what;
  try {
    (void)eical::daemon::load_daemon_config(file);
  } catch (const eical::dsp::InputError& e) {
    what = e.what();
  }
  EXPECT_NE(what.find(file.string()), std::string::npos) << what;
  return what;
}

// gpio_lines = [1e10, ...]: the offset was converted to int before its range was checked,
// undefined behaviour (UBSan: float-cast-overflow); the range is checked on the double now.
TEST(DaemonConfigFuzz, GpioLineBeyondIntIsRefusedBeforeConversion) {
  EXPECT_NE(finding_error("review-gpio-line-beyond-int")
                .find(":2: triggers.gpio_lines: line offsets must be integers within 0..65535"),
            std::string::npos);
}

}  // namespace
