#pragma once
// A whole text file as a string ("" when it cannot be read): what the tests compare
// written files with. One helper for every suite (they compile as unity batches in CI).
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

namespace test_support {

inline std::string slurp(const std::filesystem::path& p) {
  std::ifstream is(p);
  return {std::istreambuf_iterator<char>(is), std::istreambuf_iterator<char>()};
}

}  // namespace test_support
