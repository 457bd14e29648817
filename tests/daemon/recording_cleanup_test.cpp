// What an interrupted eicald leaves in its recording directory, put right at the next
// start: the run writer's temporaries removed, a run moved aside restored when its
// replacement never arrived, result.json.tmp removed, runs without result.json listed.
#include "daemon/service/recording_cleanup.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <random>

namespace {

namespace fs = std::filesystem;

void file(const fs::path& p, const std::string& text = "x") {
  fs::create_directories(p.parent_path());
  std::ofstream(p) << text;
}

TEST(RecordingCleanup, TemporariesGoRunsStayAndUnevaluatedRunsAreListed) {
  const fs::path dir = fs::temp_directory_path() / ("eicald-cleanup-" + std::to_string(std::random_device{}()));
  file(dir / "eicald-A-0" / "run.toml");
  file(dir / "eicald-A-0" / "result.json");
  file(dir / "eicald-B-5" / "run.toml");                    // written, not evaluated
  file(dir / "eicald-B-5" / "result.json.tmp");             // its result was being written
  file(dir / ".eicald-C-9.tmp-123" / "run.toml");           // a run being written
  file(dir / ".eicald-D-7.old-456" / "run.toml", "old D");  // moved aside, no replacement
  file(dir / ".eicald-D-7.old-456" / "result.json");
  file(dir / "eicald-E-3" / "run.toml");
  file(dir / "eicald-E-3" / "result.json");
  file(dir / ".eicald-E-3.old-789" / "run.toml");  // moved aside, replacement in place
  file(dir / ".eicald-check-42");
  file(dir / ".eicald-state", "kept");  // not a temporary
  file(dir / ".tmp-notours" / "x");     // not the writer's name: left alone

  const auto r = eical::daemon::clean_recording_dir(dir);
  EXPECT_EQ(r.removed, 4u);  // C's tmp, E's old, the probe, B's result.json.tmp
  EXPECT_EQ(r.restored, 1u);
  ASSERT_EQ(r.unevaluated.size(), 1u);
  EXPECT_EQ(r.unevaluated[0].filename(), "eicald-B-5");
  EXPECT_FALSE(fs::exists(dir / ".eicald-C-9.tmp-123"));
  EXPECT_FALSE(fs::exists(dir / ".eicald-E-3.old-789"));
  EXPECT_FALSE(fs::exists(dir / ".eicald-check-42"));
  EXPECT_FALSE(fs::exists(dir / "eicald-B-5" / "result.json.tmp"));
  EXPECT_TRUE(fs::exists(dir / "eicald-D-7" / "run.toml")) << "the run moved aside was not restored";
  EXPECT_TRUE(fs::exists(dir / "eicald-E-3" / "result.json"));
  EXPECT_TRUE(fs::exists(dir / ".eicald-state"));
  EXPECT_TRUE(fs::exists(dir / ".tmp-notours"));
  fs::remove_all(dir);
}

TEST(RecordingCleanup, AnAbsentDirectoryIsNothingToClean) {
  const auto r = eical::daemon::clean_recording_dir("/nonexistent/eicald-cleanup");
  EXPECT_EQ(r.removed + r.restored + r.unevaluated.size(), 0u);
}

}  // namespace
