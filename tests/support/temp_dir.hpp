#pragma once
// A directory of the test's own under the system's temporary directory, removed with all
// it holds when the test leaves its scope. One helper for every suite (they compile as
// unity batches in CI, where two file-local copies of it collided).
#include <filesystem>
#include <random>
#include <string>
#include <system_error>

namespace test_support {

struct TempDir {
  std::filesystem::path path;
  explicit TempDir(const std::string& prefix = "eical-test-")
      : path(std::filesystem::temp_directory_path() / (prefix + std::to_string(std::random_device{}()))) {
    std::filesystem::create_directories(path);
  }
  ~TempDir() {
    std::error_code ec;  // a test's failure must not become a throw from a destructor
    std::filesystem::remove_all(path, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
};

}  // namespace test_support
