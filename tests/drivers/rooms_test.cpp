// The rooms of docs/architecture.md ("Layout"), checked on the source tree: each product
// folder includes only the folders its row names, and no product file is named like a test
// (coverage and lint tools drop those). A change that crosses a room fails here, naming the
// file and the include.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;

// Folder → the include prefixes its files may use (their own folder always).
const std::map<std::string, std::vector<std::string>> kAllowed = {
    {"dsp", {"dsp/"}},
    {"sim", {"sim/", "dsp/"}},
    {"drivers", {"drivers/", "sim/", "dsp/"}},
    // A leaf: the store knows results only as JSON; the unit table is header only.
    {"history", {"history/", "dsp/core/key_unit.hpp"}},
    // The simulator only through drivers/source/sim_factory.hpp (no "sim/").
    {"daemon", {"daemon/", "history/", "drivers/", "dsp/"}},
    // daemon/system: `eical collect` runs as a systemd service and notifies like eicald.
    {"tools", {"tools/", "history/", "drivers/", "sim/", "dsp/", "daemon/system/"}},
};

std::vector<fs::path> sources(const fs::path& dir) {
  std::vector<fs::path> out;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.is_regular_file() && (e.path().extension() == ".cpp" || e.path().extension() == ".hpp"))
      out.push_back(e.path());
  return out;
}

TEST(Rooms, EachFolderIncludesOnlyWhatItsRowNames) {
  const fs::path root = EICAL_SOURCE_DIR;
  const std::regex include(R"re(^\s*#\s*include\s*"([^"]+)")re");
  int files = 0;
  for (const auto& [folder, allowed] : kAllowed)
    for (const fs::path& f : sources(root / folder)) {
      ++files;
      std::ifstream in(f);
      std::string line;
      while (std::getline(in, line)) {
        std::smatch m;
        if (!std::regex_search(line, m, include)) continue;
        const std::string target = m[1];
        if (target.find('/') == std::string::npos) continue;  // generated ("eical.h") or local
        bool ok = false;
        for (const auto& prefix : allowed) ok = ok || target.rfind(prefix, 0) == 0;
        EXPECT_TRUE(ok) << fs::relative(f, root).string() << " includes \"" << target << "\", outside the room of "
                        << folder << "/ (docs/architecture.md)";
      }
    }
  EXPECT_GT(files, 300);
}

TEST(Rooms, NoProductFileIsNamedLikeATest) {
  const fs::path root = EICAL_SOURCE_DIR;
  const std::regex test_like(R"(^(test_.*|.*_tests?)\.(cpp|hpp)$)");
  for (const auto& [folder, allowed] : kAllowed)
    for (const fs::path& f : sources(root / folder))
      EXPECT_FALSE(std::regex_match(f.filename().string(), test_like)) << fs::relative(f, root).string();
}

}  // namespace
