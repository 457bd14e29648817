#pragma once
// What every fuzz target shares. The readers take paths (as eical and eicald call them),
// so the input is written to a file in a private scratch directory first. The rule each
// target checks: bad input ends in a dsp::InputError that names the file it came from;
// any other exception, a crash, a leak, a hang or undefined behaviour is a finding
// (libFuzzer reports an escaping exception as a deadly signal).
#include "dsp/core/error.hpp"

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

namespace eical::fuzz {

// $EICAL_FUZZ_SCRATCH, else /dev/shm (no disk traffic per input) or the temp directory:
// eical-fuzz-<pid>, removed at exit.
const std::filesystem::path& scratch_dir();

// Writes `bytes` to scratch_dir()/name (replacing it) and returns the path.
std::filesystem::path write_input(const std::string& name, std::string_view bytes);
inline std::string_view as_text(const std::uint8_t* data, std::size_t size) {
  return {reinterpret_cast<const char*>(data), size};
}

// Aborts with `what` (a finding: libFuzzer saves the input).
[[noreturn]] void finding(const std::string& what);

// Runs `read`; an InputError is the expected outcome for bad input and must name `source`
// (a file or directory path, or a name given to the reader) so the user can find it.
template <class Read>
void expect_clean(const std::string& source, Read&& read) {
  try {
    read();
  } catch (const dsp::InputError& e) {
    const std::string_view msg = e.what();
    if (msg.find(source) == std::string_view::npos)
      finding("InputError does not name '" + source + "': " + std::string(msg));
  }
}

}  // namespace eical::fuzz
