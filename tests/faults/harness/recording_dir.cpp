#include "tests/faults/harness/recording_dir.hpp"

#include "drivers/run_io/run_reader.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <fstream>
#include <random>
#include <set>

namespace eical::faults {

Scratch::Scratch(const std::string& tag)
    : dir(fs::temp_directory_path() / ("eical-fault-" + tag + "-" + std::to_string(std::random_device{}()))) {
  fs::create_directories(dir);
}

Scratch::~Scratch() {
  std::error_code ec;
  fs::remove_all(dir, ec);
}

std::string slurp(const fs::path& file) {
  std::ifstream is(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(is), std::istreambuf_iterator<char>()};
}

std::vector<fs::path> completed_runs(const fs::path& recording_dir) {
  std::vector<fs::path> out;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(recording_dir, ec))
    if (e.is_directory() && e.path().filename().string()[0] != '.') out.push_back(e.path());
  std::sort(out.begin(), out.end());
  return out;
}

std::vector<fs::path> temporaries(const fs::path& recording_dir) {
  std::vector<fs::path> out;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(recording_dir, ec)) {
    const std::string name = e.path().filename().string();
    if (name == ".eicald-state") continue;  // eicald's own record of how it last ended
    if (name[0] == '.')
      out.push_back(e.path());
    else if (e.is_directory())
      for (const auto& f : fs::directory_iterator(e.path(), ec))
        if (f.path().extension() == ".tmp") out.push_back(f.path());
  }
  return out;
}

Snapshot snapshot(const fs::path& recording_dir) {
  Snapshot s;
  for (const auto& run : completed_runs(recording_dir)) {
    std::error_code ec;
    for (const auto& f : fs::directory_iterator(run, ec))
      if (f.is_regular_file()) s[run.filename().string() + "/" + f.path().filename().string()] = slurp(f.path());
  }
  return s;
}

std::size_t runs_in(const Snapshot& s) {
  std::set<std::string> runs;
  for (const auto& [key, bytes] : s) runs.insert(key.substr(0, key.find('/')));
  return runs.size();
}

bool readable_with_result(const fs::path& run, std::string* why) {
  try {
    (void)drivers::read_run(run);
    const auto result = nlohmann::json::parse(slurp(run / "result.json"));
    if (!result.contains("quality")) throw std::runtime_error("result.json has no quality section");
    return true;
  } catch (const std::exception& e) {
    if (why) *why = run.filename().string() + ": " + e.what();
    return false;
  }
}

std::size_t intact_runs(const Snapshot& before, const fs::path& recording_dir) {
  std::set<std::string> runs, broken;
  for (const auto& [key, bytes] : before) {
    const std::string run = key.substr(0, key.find('/'));
    runs.insert(run);
    std::error_code ec;
    const fs::path file = recording_dir / key;
    if (!fs::exists(file, ec) || slurp(file) != bytes) broken.insert(run);
  }
  std::size_t intact = 0;
  for (const auto& run : runs)
    if (!broken.count(run) &&
        (!fs::exists(recording_dir / run / "run.toml") || readable_with_result(recording_dir / run)))
      ++intact;
  return intact;
}

}  // namespace eical::faults
