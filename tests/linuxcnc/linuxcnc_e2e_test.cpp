// End to end with a real NC: a headless LinuxCNC (integrations/linuxcnc) runs programs
// written by `eical gen-nc`; its user M-codes call `eical trigger` (DDS); its servo-rate
// positions drive eicald's `linuxcnc` source; the Result arrives here over DDS and is
// checked against the machine error put into the simulation (4 um backlash on x).
// Needs LinuxCNC (scripts/deps.sh test installs linuxcnc-uspace); without it the test
// fails saying so. EICAL_SKIP_LINUXCNC=1 skips it on purpose.
#include "lcnc_harness.hpp"

#include <cmath>
#include <cstdio>

namespace eical::test {
namespace {

constexpr double kE2eBacklashXUm = 4.0;

// A real position loop (as config/scenarios/backlash-circle.toml): with an ideal,
// infinitely stiff one the play operator picks the slide up with a velocity step.
std::string e2e_machine() {
  return "[servo.x]\nkv_per_s = 33.3\nfeedforward = 0.99\n[servo.y]\nkv_per_s = 33.3\nfeedforward = 0.99\n"
         "[effects.\"machine.backlash\"]\naxis = \"x\"\nvalue_um = " +
         std::to_string(kE2eBacklashXUm) + "\n";
}

ProgramOutcome run_program(const std::string& tag, const std::vector<std::string>& gen_args) {
  LcncProgram p;
  p.tag = tag;
  p.gen_args = gen_args;
  p.machine = e2e_machine();
  return eical::test::run_program(p);
}

// Every trigger in a standstill, and how far it is from the motion around it.
void check_and_print_timing(const std::string& what, const ProgramOutcome& o) {
  ASSERT_FALSE(o.triggers.empty());
  std::printf("%s: %s\n", what.c_str(), o.stream_stats.c_str());
  double lo = 1e9, hi = 0;
  for (const auto& t : o.triggers) {
    std::printf("  M%d: %.1f ms after motion stopped, %.1f ms before the next motion\n", t.code, t.after_stop_ms,
                t.before_move_ms);
    EXPECT_FALSE(t.after_stop_ms == 0.0) << "M" << t.code << " landed inside a move";
    EXPECT_FALSE(t.before_move_ms <= 0.0) << "M" << t.code << " landed inside a move";
    if (t.code == 102 && std::isfinite(t.after_stop_ms))
      lo = std::min(lo, t.after_stop_ms), hi = std::max(hi, t.after_stop_ms);
  }
  std::printf("  trigger latency (M102, motion stop -> eical trigger's time on the DAQ clock): %.1f .. %.1f ms\n", lo,
              hi);
  // Alignment: the script's marker in the servo stream against the trigger eicald placed
  // from eical trigger's CLOCK_MONOTONIC time and the servo clock.
  std::size_t k = 0;
  for (const auto& [code, sample] : o.trigger_samples) {
    while (k < o.markers.size() && o.markers[k].first != code) ++k;
    if (k == o.markers.size()) break;
    const double d_ms = static_cast<double>(sample - o.markers[k].second) * 0.1;
    std::printf("  M%d: marker at sample %lld, trigger at sample %lld: trigger - marker = %.1f ms\n", code,
                static_cast<long long>(o.markers[k].second), static_cast<long long>(sample), d_ms);
    // eical trigger reads its clock after halcmd set the marker: later, by a process start
    // and a DDS participant (48–131 ms here while CI compiles the ASan tree beside it; the
    // figure is printed above, a latency target belongs in a benchmark). A clock off by its
    // alignment is off by the servo stream's buffering, hundreds of ms or more, or early.
    EXPECT_GT(d_ms, -2.0) << "trigger before the script ran: clock alignment off";
    EXPECT_LT(d_ms, 400.0) << "trigger far behind the script: clock alignment off";
    ++k;
  }
}

TEST(LinuxcncE2E, CircleBothDirectionsAndIso230_2OnLinuxCncMatchTheInjectedBacklash) {
  require_linuxcnc();
  if (HasFatalFailure() || IsSkipped()) return;
  for (const char* dir : {"ccw", "cw"}) {
    const auto o = run_program(std::string("circle-") + dir,
                               {"circle", "--radius", "10", "--feed", "2500", "--repeats", "2", "--direction", dir});
    ASSERT_TRUE(o.result.contains("circle")) << o.result.dump();
    const auto& c = o.result["circle"];
    const auto& d = o.result["diagnostics"];
    std::printf(
        "circle %s on LinuxCNC: G %.2f um, mean radius deviation %.2f um, backlash x %.2f um (injected %.1f), backlash "
        "y %.2f um (injected 0), degraded %d\n",
        dir, c["circular_deviation_G_um"].get<double>(), c["radius_mean_deviation_um"].get<double>(),
        d["backlash_x_um"].get<double>(), kE2eBacklashXUm, d["backlash_y_um"].get<double>(),
        o.result["quality"]["degraded"].get<bool>());
    check_and_print_timing(std::string("circle ") + dir, o);
    // The ballbar-style fit of the play on x; its residual is the model's own scatter.
    // Measured here: 2.2..3.4 um for 4 um injected, |y| <= 1.2 um (4 runs). Tolerance:
    // the fit's noise, taken as five times its residual rms (~0.45 um).
    const double tol = 5.0 * d["model_residual_rms_um"].get<double>();
    EXPECT_NEAR(d["backlash_x_um"].get<double>(), kE2eBacklashXUm, tol);
    EXPECT_NEAR(d["backlash_y_um"].get<double>(), 0.0, tol);
    EXPECT_FALSE(o.result["quality"]["degraded"].get<bool>()) << o.result["quality"].dump();
  }
  const auto p = run_program("positioning", {"positioning", "--axis", "x", "--targets", "0,10,20,30", "--runs", "2",
                                             "--feed", "2000", "--dwell", "0.3"});
  ASSERT_TRUE(p.result.contains("positioning")) << p.result.dump();
  const auto& pos = p.result["positioning"];
  std::printf(
      "ISO 230-2 on LinuxCNC: B %.2f um, mean B %.2f um (injected backlash %.1f um), E %.2f um, M %.2f um, R %.2f um, "
      "A %.2f um\n",
      pos["B_um"].get<double>(), pos["B_mean_um"].get<double>(), kE2eBacklashXUm, pos["E_um"].get<double>(),
      pos["M_um"].get<double>(), pos["R_um"].get<double>(), pos["A_um"].get<double>());
  check_and_print_timing("positioning", p);
  // ISO 230-2 B = mean up - mean down; the play shifts every approach from below by -b.
  // Tolerance from this run's own scatter: one reading has s ~ R/4, B_mean averages
  // targets x runs readings per direction; 3 sigma.
  const double n = static_cast<double>(pos["targets_mm"].size() * pos["runs"].get<std::size_t>());
  const double tol_b = 3.0 * pos["R_um"].get<double>() / 4.0 * std::sqrt(2.0 / n);
  std::printf("ISO 230-2: mean B %.2f um, expected %.2f +- %.2f um (3 sigma from R)\n", pos["B_mean_um"].get<double>(),
              -kE2eBacklashXUm, tol_b);
  EXPECT_NEAR(pos["B_mean_um"].get<double>(), -kE2eBacklashXUm, tol_b);
}

}  // namespace
}  // namespace eical::test
