// [source.sim] program_file and [source.fault]: a gen-nc program table is read with its
// G-code; a file without [program] or a mistyped fault key is an error naming the cause.
#include "daemon/config/daemon_config.hpp"
#include "dsp/core/error.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <random>

namespace {

namespace fs = std::filesystem;

fs::path temp(const std::string& name, const std::string& text) {
  const fs::path p = fs::temp_directory_path() / ("eicald-prog-" + std::to_string(std::random_device{}()) + "-" + name);
  std::ofstream(p) << text;
  return p;
}

std::string load_error(const fs::path& cfg) {
  try {
    (void)eical::daemon::load_daemon_config(cfg);
  } catch (const eical::dsp::InputError& e) {
    return e.what();
  }
  return "";
}

TEST(DaemonConfigProgram, ReadsTheGenNcProgramTableWithItsGcode) {
  const auto prog =
      temp("p.toml",
           "[program]\nkind = \"circle\"\nplane = \"xy\"\nfeed_mm_min = 2000.0\ncenter_mm = [0.0, 0.0]\n"
           "radius_mm = 7.5\ndirection = \"cw\"\nrepeats = 3\ngcode = \"\"\"\nG17 G21 G90\nM101\nM103\nM2\n\"\"\"\n");
  const auto cfg = temp("c.toml", "[source.sim]\nprogram_file = \"" + prog.string() +
                                      "\"\n[source.fault]\ngap_at_s = 2.5\ngap_frames = 10\n");
  const auto c = eical::daemon::load_daemon_config(cfg);
  ASSERT_TRUE(c.source.sim_program_loaded);
  EXPECT_EQ(c.source.sim_program_loaded->kind, eical::dsp::ProgramKind::circle);
  EXPECT_DOUBLE_EQ(c.source.sim_program_loaded->radius_mm, 7.5);
  EXPECT_EQ(c.source.sim_program_loaded->direction, "cw");
  EXPECT_NE(c.source.sim_program_loaded->gcode.find("M101"), std::string::npos);
  EXPECT_DOUBLE_EQ(c.source.fault.gap_at_s, 2.5);
  EXPECT_EQ(c.source.fault.gap_frames, 10);
  EXPECT_TRUE(c.source.fault.any());
  fs::remove(prog);
  fs::remove(cfg);
}

TEST(DaemonConfigProgram, ProgramFileWithoutProgramTableIsAClearError) {
  const auto prog = temp("p.toml", "[machine]\nname = \"x\"\n");
  const auto cfg = temp("c.toml", "[source.sim]\nprogram_file = \"" + prog.string() + "\"\n");
  const std::string e = load_error(cfg);
  EXPECT_NE(e.find("program_file"), std::string::npos) << e;
  fs::remove(prog);
  fs::remove(cfg);
}

TEST(DaemonConfigProgram, MistypedFaultKeyIsAnError) {
  const auto cfg = temp("c.toml", "[source.fault]\ngap_at = 2.5\n");
  const std::string e = load_error(cfg);
  EXPECT_NE(e.find("gap_at"), std::string::npos) << e;
  EXPECT_NE(e.find(":2"), std::string::npos) << "no line number: " << e;
  fs::remove(cfg);
}

}  // namespace
