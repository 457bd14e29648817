#pragma once
// The test of every reader against an unknown name (issue 32): each suite lists its readers
// as Cases and instantiates UnknownName with them. A reader must read its valid input,
// refuse an unknown name with the file, the line and the name, and pass over a name of the
// extension namespace ext_ (docs/run-files.md).
#include "dsp/core/error.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <random>
#include <sstream>
#include <string>
#include <vector>

namespace eical::test_support {

namespace fs = std::filesystem;

inline std::string slurp(const fs::path& p) {
  std::ifstream is(p);
  return {std::istreambuf_iterator<char>(is), std::istreambuf_iterator<char>()};
}

inline void write(const fs::path& p, const std::string& text) { std::ofstream(p) << text; }

inline std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream is(text);
  for (std::string l; std::getline(is, l);) out.push_back(l);
  return out;
}

inline std::string joined(const std::vector<std::string>& lines) {
  std::string out;
  for (const auto& l : lines) out += l + "\n";
  return out;
}

// One reader: where its input goes, how a valid one is made, how it is read, and where an
// unknown name is put in (TOML: a key after the first line that begins with `after`, or
// the `prefix` lines and the key at the end when `after` is empty; CSV: a last column).
struct Case {
  std::string name;
  std::string file;  // relative to the case's directory
  std::function<void(const fs::path& dir)> make;
  std::function<void(const fs::path& dir)> read;
  bool csv = false;
  std::string after;
  std::string prefix;        // TOML at the end: e.g. "[sensors]" to put the key in that table
  bool extension_ok = true;  // false: a fixed foreign format with no room for other columns
};

inline std::ostream& operator<<(std::ostream& os, const Case& c) { return os << c.name; }

// The input with `name` added; returns the line the name is on.
inline std::size_t add_name(const Case& c, const fs::path& file, const std::string& name) {
  auto lines = lines_of(slurp(file));
  std::size_t at = 0;
  if (c.csv) {
    lines[0] += "," + name;
    for (std::size_t i = 1; i < lines.size(); ++i)
      if (!lines[i].empty()) lines[i] += ",0";
    at = 1;
  } else if (c.after.empty()) {
    if (!c.prefix.empty()) lines.push_back(c.prefix);
    lines.push_back(name + " = 1");
    at = lines.size();
  } else {
    std::size_t i = 0;
    while (i < lines.size() && lines[i].rfind(c.after, 0) != 0) ++i;
    EXPECT_LT(i, lines.size()) << c.after << " is not in " << file;
    lines.insert(lines.begin() + static_cast<std::ptrdiff_t>(i + 1), name + " = 1");
    at = i + 2;
  }
  write(file, joined(lines));
  return at;
}

class UnknownName : public ::testing::TestWithParam<Case> {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("eical-unknown-" + std::to_string(std::random_device{}()));
    fs::create_directories(dir_);
    GetParam().make(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

TEST_P(UnknownName, ValidInputIsRead) { EXPECT_NO_THROW(GetParam().read(dir_)); }

TEST_P(UnknownName, IsRefusedWithFileLineAndName) {
  const Case& c = GetParam();
  const fs::path file = dir_ / c.file;
  const std::size_t line = add_name(c, file, c.csv ? "typo_col" : "typo_key");
  try {
    c.read(dir_);
    FAIL() << c.name << ": an unknown name was read without a word";
  } catch (const dsp::InputError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find(file.string() + ":" + std::to_string(line) + ":"), std::string::npos)
        << "expected " << file.string() << ":" << line << " in: " << msg;
    EXPECT_NE(msg.find(c.csv ? "typo_col" : "typo_key"), std::string::npos) << msg;
  }
}

TEST_P(UnknownName, ExtensionNamespaceIsPassedOver) {
  const Case& c = GetParam();
  if (!c.extension_ok) GTEST_SKIP() << c.name << " is a fixed foreign format";
  add_name(c, dir_ / c.file, "ext_note");
  EXPECT_NO_THROW(c.read(dir_));
}

inline Case toml_case(const std::string& name, const std::string& file, std::function<void(const fs::path&)> make,
                      std::function<void(const fs::path&)> read, const std::string& after) {
  return {name, file, std::move(make), std::move(read), false, after, ""};
}

inline Case csv_case(const std::string& name, const std::string& file, std::function<void(const fs::path&)> make,
                     std::function<void(const fs::path&)> read, bool extension_ok = true) {
  return {name, file, std::move(make), std::move(read), true, "", "", extension_ok};
}

}  // namespace eical::test_support
