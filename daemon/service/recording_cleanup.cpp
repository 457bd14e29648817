#include "daemon/service/recording_cleanup.hpp"

#include <string>

namespace eical::daemon {
namespace fs = std::filesystem;
namespace {

// ".<run>.<kind>-<digits>" as drivers/run_io/run_writer.cpp names its temporaries: the run's
// name, or empty when `name` is not one.
std::string writer_temporary(const std::string& name, const std::string& kind) {
  const std::string mark = "." + kind + "-";
  const auto at = name.rfind(mark);
  if (name.size() < 2 || name[0] != '.' || at == std::string::npos || at < 2) return {};
  const std::string digits = name.substr(at + mark.size());
  if (digits.empty() || digits.find_first_not_of("0123456789") != std::string::npos) return {};
  return name.substr(1, at - 1);
}

}  // namespace

RecordingCleanup clean_recording_dir(const fs::path& dir) {
  RecordingCleanup r;
  std::error_code ec;
  std::vector<fs::path> entries;
  for (const auto& e : fs::directory_iterator(dir, ec)) entries.push_back(e.path());
  for (const auto& path : entries) {
    const std::string name = path.filename().string();
    if (!writer_temporary(name, "tmp").empty() || name.rfind(".eicald-check-", 0) == 0) {
      if (fs::remove_all(path, ec) > 0 && !ec) ++r.removed;
    } else if (const std::string run = writer_temporary(name, "old"); !run.empty()) {
      if (!fs::exists(dir / run, ec)) {
        fs::rename(path, dir / run, ec);
        r.restored += ec ? 0 : 1;
      } else if (fs::remove_all(path, ec) > 0 && !ec) {
        ++r.removed;
      }
    }
  }
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    if (!e.is_directory() || e.path().filename().string()[0] == '.' || !fs::exists(e.path() / "run.toml", ec)) continue;
    if (fs::remove(e.path() / "result.json.tmp", ec)) ++r.removed;
    if (!fs::exists(e.path() / "result.json", ec)) r.unevaluated.push_back(e.path());
  }
  return r;
}

}  // namespace eical::daemon
