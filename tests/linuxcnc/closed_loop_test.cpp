// Compensation that closes the loop (issue 19): a simulated machine with a known pitch
// error and backlash on x and a squareness error in xy, driven by a headless LinuxCNC
// (integrations/linuxcnc), runs the ISO 230-2 and circle programs of `eical gen-nc`;
// `eical comp` turns the results into a LinuxCNC COMP_FILE and INI merged into the
// machine's INI; LinuxCNC runs the programs again with those files as written; ISO 230-2
// A and B and the circle's backlash must drop by 80 % or more.
//
// The compensation acts on joint.N.motor-pos-cmd; the kit samples joint.N.pos-cmd as the
// set-point the evaluation uses and motor-pos-fb (the simulated plant after the
// compensated motor command) as what drives eical's machine model: drive = "feedback".
#include "lcnc_harness.hpp"

#include <cmath>
#include <cstdio>

namespace eical::test {
namespace {

// A worn machine: 15 µm play and a rolled ball screw's 500 ppm lead error (20 µm over the
// 40 mm measured): large against the ~1 µm scatter of the measurement, so that an 80 %
// drop of ISO 230-2 A (which keeps 4 s) is a test of the compensation, not of luck. A lead
// error is a scale: against the sensors' data-sheet scale (of the same size) it is only
// resolved where PSD strips fix two positions along the axis — with one strip at the
// origin U(M) came out at M itself (19.5 against 19.3 µm) and the table was left out.
constexpr double kBacklashXUm = 15.0;
constexpr double kScaleXPpm = 500.0;
constexpr double kSquarenessUrad = 40.0;

std::string machine() {
  return "[servo.x]\nkv_per_s = 33.3\nfeedforward = 0.99\n[servo.y]\nkv_per_s = 33.3\nfeedforward = 0.99\n"
         "[effects.\"machine.backlash\"]\naxis = \"x\"\nvalue_um = " +
         std::to_string(kBacklashXUm) +
         "\n[effects.\"machine.scale_mismatch\"]\naxis = \"x\"\nvalue_ppm = " + std::to_string(kScaleXPpm) +
         "\n[effects.\"machine.squareness\"]\nplane = \"xy\"\nvalue_urad = " + std::to_string(kSquarenessUrad) +
         "\n"
         // The instrument as the embedded calibrator has it: PSD strips on x at the origin
         // and at +20 mm hold the integration between the standstills (CUPT), so ISO
         // 230-2's scatter is the machine's and not the integration's drift over a minute
         // of moves, and the two fixed positions resolve the lead error against the sensors'
         // scale.
         "[[psd]]\nmeasures = \"x\"\ncenter_mm = [0.0, 0.0]\nlength_mm = 10.0\nwidth_mm = 0.5\nlockin_tau_s = 2.0e-5\n"
         "[[psd]]\nmeasures = \"x\"\ncenter_mm = [20.0, 0.0]\nlength_mm = 10.0\nwidth_mm = 0.5\nlockin_tau_s = "
         "2.0e-5\n";
}

// ISO 230-2 over the circle's x travel and beyond, 5 runs; a circle both ways.
const std::vector<std::string> kPositioning = {
    "positioning", "--axis", "x", "--targets", "-20,-10,0,10,20", "--runs", "5", "--feed", "2000", "--dwell", "0.3"};
const std::vector<std::string> kCircle = {"circle",    "--radius", "10",          "--feed", "2500",
                                          "--repeats", "2",        "--direction", "both"};

struct Figures {
  double A_um = std::nan(""), B_um = std::nan(""), B_mean_um = std::nan(""), backlash_x_um = std::nan(""),
         backlash_y_um = std::nan(""), squareness_urad = std::nan("");
};

ProgramOutcome run(const std::string& tag, const std::vector<std::string>& gen, const fs::path& config) {
  LcncProgram p;
  p.tag = tag;
  p.gen_args = gen;
  p.machine = machine();
  p.config = config;
  p.drive = "feedback";
  return run_program(p);
}

double number(const nlohmann::json& j, const char* section, const char* key) {
  return j.contains(section) && j[section].contains(key) && j[section][key].is_number() ? j[section][key].get<double>()
                                                                                        : std::nan("");
}

// `eical analyze RUN --json` → file: what the user hands to eical comp.
fs::path analyze(const ProgramOutcome& o, const fs::path& file) {
  int rc = -1;
  const auto out = run_capture({EICAL_CLI, "analyze", o.run_dir.string(), "--json"}, 120s, &rc);
  // Exit status: the verdict's (0 ok, 2 degraded, 3 not measurable); 1 is an error.
  EXPECT_TRUE(out && (rc == 0 || rc == 2 || rc == 3)) << "eical analyze " << o.run_dir << " exited " << rc;
  std::ofstream(file) << out.value_or("");
  return file;
}

TEST(LinuxcncClosedLoop, CompensationFromEicalCompDropsIso230_2AandBandTheCircleBacklash) {
  require_linuxcnc();
  if (HasFatalFailure() || IsSkipped()) return;
  const fs::path work = scratch_dir("closed-loop");
  fs::copy(kit(), work / "machine", fs::copy_options::recursive);  // the machine's configuration folder

  // Before: the machine as it is.
  const ProgramOutcome pos0 = run("pos-before", kPositioning, work / "machine");
  const ProgramOutcome circ0 = run("circle-before", kCircle, work / "machine");
  ASSERT_FALSE(pos0.run_dir.empty() || circ0.run_dir.empty()) << "a run was not recorded";
  const fs::path pos0_json = analyze(pos0, work / "pos-before.json"),
                 circ0_json = analyze(circ0, work / "circle-before.json");

  // eical comp: LinuxCNC files merged into the machine's INI.
  // --skip-unresolved, as a user told so by eical comp: y has no backlash, and its circle
  // figure (about 1 um against a U of 1.5 um) is not resolved; the x terms compensated here are
  // far above their uncertainty. Never --allow-unresolved.
  int rc = -1;
  const auto comp_out =
      run_capture({EICAL_CLI, "comp", pos0_json.string(), circ0_json.string(), "-o", (work / "comp").string(),
                   "--merge-ini", (work / "machine" / "eical-sim3.ini").string(), "--skip-unresolved"},
                  60s, &rc);
  ASSERT_TRUE(comp_out && rc == 0) << "eical comp failed:\n" << comp_out.value_or("");
  std::printf("%s", comp_out->c_str());
  // The compensated machine: its folder with eical comp's LinuxCNC files copied in as
  // written (the merged INI replaces the machine's; the COMP_FILEs sit next to it).
  fs::copy(work / "machine", work / "machine-comp", fs::copy_options::recursive);
  for (const auto& f : fs::directory_iterator(work / "comp" / "linuxcnc"))
    fs::copy_file(f.path(), work / "machine-comp" / f.path().filename(), fs::copy_options::overwrite_existing);
  std::printf("merged INI, joint sections:\n");
  {
    std::ifstream ini(work / "machine-comp" / "eical-sim3.ini");
    bool in_joint = false;
    for (std::string l; std::getline(ini, l);) {
      if (!l.empty() && l[0] == '[') in_joint = l.rfind("[JOINT_", 0) == 0;
      if (in_joint && (l.find("COMP") != std::string::npos || l.find("BACKLASH") != std::string::npos || l[0] == '[' ||
                       l[0] == '#'))
        std::printf("  %s\n", l.c_str());
    }
  }

  // After: the same programs on the compensated machine.
  const ProgramOutcome pos1 = run("pos-after", kPositioning, work / "machine-comp");
  const ProgramOutcome circ1 = run("circle-after", kCircle, work / "machine-comp");
  ASSERT_FALSE(pos1.run_dir.empty() || circ1.run_dir.empty()) << "a run was not recorded";

  auto figures = [](const ProgramOutcome& p, const ProgramOutcome& c) {
    Figures f;
    f.A_um = number(p.result, "positioning", "A_um");
    f.B_um = number(p.result, "positioning", "B_um");
    f.B_mean_um = number(p.result, "positioning", "B_mean_um");
    f.backlash_x_um = number(c.result, "diagnostics", "backlash_x_um");
    f.backlash_y_um = number(c.result, "diagnostics", "backlash_y_um");
    f.squareness_urad = number(c.result, "diagnostics", "squareness_urad");
    return f;
  };
  const Figures b = figures(pos0, circ0), a = figures(pos1, circ1);
  {  // what eical comp decides on: the lead error's M against its U
    std::ifstream in(pos0_json);
    const nlohmann::json j = nlohmann::json::parse(in, nullptr, false);
    const double m_um = number(j, "positioning", "M_um"), u_um = number(j, "uncertainty_k2", "positioning.M_um");
    std::printf("positioning before: M = %.2f um, U = %.2f um (k = 2)\n", m_um, u_um);
    EXPECT_GT(m_um, u_um) << "the lead error is not resolved: eical comp leaves the x table out";
  }
  auto drop = [](double before, double after) { return 100.0 * (1.0 - std::abs(after) / std::abs(before)); };
  std::printf("closed loop on LinuxCNC (x: %.0f um backlash, %.0f ppm pitch error; xy squareness %.0f urad)\n",
              kBacklashXUm, kScaleXPpm, kSquarenessUrad);
  std::printf("  figure                     before      after    drop\n");
  std::printf("  ISO 230-2 A (um)         %8.2f   %8.2f   %5.1f %%\n", b.A_um, a.A_um, drop(b.A_um, a.A_um));
  std::printf("  ISO 230-2 B (um)         %8.2f   %8.2f   %5.1f %%\n", b.B_um, a.B_um, drop(b.B_um, a.B_um));
  std::printf("  ISO 230-2 mean B (um)    %8.2f   %8.2f   %5.1f %%\n", b.B_mean_um, a.B_mean_um,
              drop(b.B_mean_um, a.B_mean_um));
  std::printf("  circle backlash x (um)   %8.2f   %8.2f   %5.1f %%\n", b.backlash_x_um, a.backlash_x_um,
              drop(b.backlash_x_um, a.backlash_x_um));
  std::printf("  circle backlash y (um)   %8.2f   %8.2f   (none injected)\n", b.backlash_y_um, a.backlash_y_um);
  std::printf("  squareness xy (urad)     %8.1f   %8.1f   (injected %.0f; not compensable with trivkins)\n",
              b.squareness_urad, a.squareness_urad, kSquarenessUrad);
  EXPECT_GE(drop(b.A_um, a.A_um), 80.0);
  EXPECT_GE(drop(b.B_um, a.B_um), 80.0);
  EXPECT_GE(drop(b.backlash_x_um, a.backlash_x_um), 80.0);
  // The squareness is only printed: no LinuxCNC joint table can change it, and on this
  // path the circle's estimate of it scatters (−6 … −29 µrad for the +40 injected in four
  // runs; +52 from eical simulate of the same machine) — reported, not asserted.
  fs::remove_all(work);
}

}  // namespace
}  // namespace eical::test
