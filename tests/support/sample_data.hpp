#pragma once
// The sample runs the tests read (tests/data/README.md): the committed ones, in every clone,
// and the extra ones of EICAL_EXTRA_DATA when that folder exists.
#include <algorithm>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <system_error>
#include <vector>

namespace eical::test {

inline std::filesystem::path committed_data() { return EICAL_TEST_DATA; }
inline std::filesystem::path extra_data() { return EICAL_EXTRA_DATA; }

// The run directories (those holding run.toml) in `root`, and in its subfolders when
// `recursive`, sorted. None when `root` does not exist.
inline std::vector<std::filesystem::path> runs_in(const std::filesystem::path& root, bool recursive) {
  namespace fs = std::filesystem;
  std::vector<fs::path> runs;
  std::error_code ec;
  if (!fs::is_directory(root, ec)) return runs;
  auto take = [&](const fs::path& p) {
    if (fs::exists(p / "run.toml")) runs.push_back(p);
  };
  if (recursive)
    for (const auto& e : fs::recursive_directory_iterator(root, ec)) take(e.path());
  else
    for (const auto& e : fs::directory_iterator(root, ec)) take(e.path());
  std::sort(runs.begin(), runs.end());
  return runs;
}

// The committed runs; throws naming the folder when there are none (a clone without them
// must fail, not pass with zero cases).
inline std::vector<std::filesystem::path> committed_runs(bool recursive = true) {
  auto runs = runs_in(committed_data(), recursive);
  if (runs.empty())
    throw std::runtime_error("no sample runs in " + committed_data().string() + " (tests/data is part of the repo)");
  return runs;
}

// The extra runs whose directory name no committed run has; none when the folder is absent.
inline std::vector<std::filesystem::path> extra_runs(bool recursive = true) {
  const auto committed = runs_in(committed_data(), true);
  std::vector<std::filesystem::path> out;
  for (const auto& r : runs_in(extra_data(), recursive))
    if (std::none_of(committed.begin(), committed.end(),
                     [&](const std::filesystem::path& c) { return c.filename() == r.filename(); }))
      out.push_back(r);
  return out;
}

// Committed and extra runs together.
inline std::vector<std::filesystem::path> all_runs(bool recursive = true) {
  auto runs = committed_runs(recursive);
  const auto more = extra_runs(recursive);
  runs.insert(runs.end(), more.begin(), more.end());
  return runs;
}

}  // namespace eical::test
