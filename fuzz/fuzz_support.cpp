#include "fuzz/fuzz_support.hpp"

#include <unistd.h>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <system_error>

namespace eical::fuzz {
namespace fs = std::filesystem;
namespace {

fs::path make_scratch() {
  fs::path base;
  if (const char* env = std::getenv("EICAL_FUZZ_SCRATCH"); env && *env)
    base = env;
  else if (fs::is_directory("/dev/shm") && ::access("/dev/shm", W_OK) == 0)
    base = "/dev/shm";
  else
    base = fs::temp_directory_path();
  fs::path dir = base / ("eical-fuzz-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  return dir;
}

}  // namespace

const fs::path& scratch_dir() {
  static const fs::path dir = [] {
    fs::path d = make_scratch();
    std::atexit([] {
      std::error_code ec;
      fs::remove_all(scratch_dir(), ec);
    });
    return d;
  }();
  return dir;
}

fs::path write_input(const std::string& name, std::string_view bytes) {
  const fs::path p = scratch_dir() / name;
  std::ofstream os(p, std::ios::binary | std::ios::trunc);
  os.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  if (!os) finding("cannot write the fuzz input to " + p.string());
  return p;
}

void finding(const std::string& what) {
  std::fprintf(stderr, "eical fuzz finding: %s\n", what.c_str());
  std::abort();
}

}  // namespace eical::fuzz
