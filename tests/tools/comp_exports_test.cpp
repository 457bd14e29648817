// One sign convention across every export: each control's file, read back the way its
// documentation says the control uses it, applied to the deviations it came from, leaves
// zero within the format's rounding. And golden files: the exact text of each format.
// The readers here model the controls (independently of the writers): what the control
// adds to the commanded position at a nominal position and direction of travel.
#include "dsp/comp/axis_table.hpp"
#include "dsp/core/error.hpp"
#include "tools/comp/fanuc_export.hpp"
#include "tools/comp/heidenhain_export.hpp"
#include "tools/comp/linuxcnc_export.hpp"
#include "tools/comp/sinumerik_export.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <sstream>

namespace eical::tools::comp {
namespace {

namespace fs = std::filesystem;
using dsp::comp::Approach;
using dsp::comp::AxisTable;

// x: lead error 100 ppm with a bow, 6 µm play; zero deviation at 0 (the FANUC reference).
AxisTable sample_table() {
  AxisTable t;
  t.axis = 0;
  for (int i = 0; i <= 4; ++i) {
    const double x = -20.0 + 10.0 * i, mean = 0.1 * x + 0.004 * x * x;
    t.pos_mm.push_back(x);
    t.forward_um.push_back(mean - 3.0);
    t.reverse_um.push_back(mean + 3.0);
  }
  return t;
}

std::vector<AxisProposal> sample_proposals() {
  AxisProposal x;
  x.axis = 0;
  x.table = sample_table();
  x.source = "test table";
  AxisProposal y;
  y.axis = 1;
  y.lost_motion_um = 4.0;
  y.source = "test backlash";
  return {x, y};
}

const std::string* find(const std::vector<OutputFile>& files, const std::string& path) {
  for (const auto& f : files)
    if (f.path == path) return &f.text;
  return nullptr;
}

double interp(const std::vector<double>& x, const std::vector<double>& y, double at) {
  if (at <= x.front()) return y.front();
  if (at >= x.back()) return y.back();
  std::size_t i = 1;
  while (x[i] < at) ++i;
  return y[i - 1] + (at - x[i - 1]) / (x[i] - x[i - 1]) * (y[i] - y[i - 1]);
}

// What a control adds to the command (µm) at position x moving in `a`.
using ControlModel = std::function<double(double x_mm, Approach a)>;

double worst_residual_um(const AxisTable& t, const ControlModel& control) {
  double worst = 0.0;
  for (std::size_t i = 0; i < t.pos_mm.size(); ++i)
    for (Approach a : {Approach::forward, Approach::reverse}) {
      const double dev = a == Approach::forward ? t.forward_um[i] : t.reverse_um[i];
      worst = std::max(worst, std::abs(dev + control(t.pos_mm[i], a)));
    }
  return worst;
}

// LinuxCNC (usrmotintf.cc usrmotLoadComp, control.c): triplets until the first line that
// is not one; trim = nominal − value (type 0), added to the motor command.
ControlModel linuxcnc_model(const std::string& comp_file) {
  std::vector<double> nom, fwd, rev;
  std::istringstream is(comp_file);
  for (std::string line; std::getline(is, line);) {
    double n, f, r;
    if (std::sscanf(line.c_str(), "%lf %lf %lf", &n, &f, &r) != 3) break;
    nom.push_back(n), fwd.push_back((n - f) * 1e3), rev.push_back((n - r) * 1e3);
  }
  return [=](double x, Approach a) { return interp(nom, a == Approach::forward ? fwd : rev, x); };
}

// LinuxCNC BACKLASH without a COMP_FILE: +b/2 moving +, −b/2 moving − (control.c).
ControlModel linuxcnc_backlash_model(double backlash_mm) {
  return [=](double, Approach a) { return (a == Approach::forward ? 0.5 : -0.5) * backlash_mm * 1e3; };
}

// SINUMERIK MSEC: value at equidistant points from MIN every STEP; "a positive
// compensation value causes the machine axis to move in the negative direction"; MD32450
// adds the lost motion at reversals (modelled symmetric: its split is a constant).
ControlModel sinumerik_model(const std::string& eec, const std::string& axis, double backlash_mm) {
  std::map<int, double> values;
  double step = 0, min = 0;
  std::istringstream is(eec);
  for (std::string l; std::getline(is, l);) {
    int n;
    double v;
    char name[16];
    if (std::sscanf(l.c_str(), "$AA_ENC_COMP[0,%d,%15[^]]]=%lf", &n, name, &v) == 3 && axis == name)
      values[n] = v * 1e3;
    if (l.rfind("$AA_ENC_COMP_STEP[0," + axis + "]=", 0) == 0) step = std::stod(l.substr(l.find('=') + 1));
    if (l.rfind("$AA_ENC_COMP_MIN[0," + axis + "]=", 0) == 0) min = std::stod(l.substr(l.find('=') + 1));
  }
  std::vector<double> x, v;
  for (const auto& [n, val] : values) x.push_back(min + n * step), v.push_back(val);
  return [=](double at, Approach a) {
    return -interp(x, v, at) + (a == Approach::forward ? 0.5 : -0.5) * backlash_mm * 1e3;
  };
}

// FANUC: the amount is 0 at the reference point (No. 3620) and changes by each point's
// value over the section that ends at it; amount added to the command (eical's reading);
// No. 1851 the lost motion at reversals (symmetric, as above).
ControlModel fanuc_model(const std::string& tape, const std::string& table, double unit_um) {
  auto param = [&](int number) {
    char key[16];
    std::snprintf(key, sizeof key, "N%05dA1P", number);
    const auto at = tape.find(key);
    return at == std::string::npos ? 0LL : std::stoll(tape.substr(at + std::strlen(key)));
  };
  const long long ref = param(3620), lo = param(3621), hi = param(3622), step_units = param(3624),
                  b_units = param(1851);
  std::map<long long, long long> value;
  std::istringstream is(table);
  for (std::string l; std::getline(is, l);) {
    long long n, v;
    double pos;
    if (std::sscanf(l.c_str(), "%lld %lf %lld", &n, &pos, &v) == 3) value[n] = v;
  }
  std::vector<double> x, amount;
  for (long long n = lo; n <= hi; ++n) {
    long long s = 0;
    if (n > ref)
      for (long long k = ref + 1; k <= n; ++k) s += value[k];
    else
      for (long long k = n + 1; k <= ref; ++k) s -= value[k];
    x.push_back(static_cast<double>((n - ref) * step_units) * unit_um * 1e-3);
    amount.push_back(static_cast<double>(s) * unit_um);
  }
  return [=](double at, Approach a) {
    return interp(x, amount, at) + (a == Approach::forward ? 0.5 : -0.5) * static_cast<double>(b_units) * unit_um;
  };
}

// HEIDENHAIN .COM: the error curve, the axis column moving +, BACKLASH moving −; the
// control removes the error (correction = −value).
ControlModel heidenhain_model(const std::string& com) {
  std::vector<double> x, fwd, rev;
  std::istringstream is(com);
  for (std::string l; std::getline(is, l);) {
    int nr;
    double p, f, r;
    if (std::sscanf(l.c_str(), "%d %lf %lf %lf", &nr, &p, &f, &r) == 4)
      x.push_back(p), fwd.push_back(f * 1e3), rev.push_back(r * 1e3);
  }
  return [=](double at, Approach a) { return -interp(x, a == Approach::forward ? fwd : rev, at); };
}

TEST(CompExports, EveryControlsTableAppliedToTheMeasuredDeviationLeavesZero) {
  const auto props = sample_proposals();
  const AxisTable t = sample_table();
  const AxisTable y_play = dsp::comp::fold_lost_motion(1, {-10.0, 10.0}, {0.0, 0.0}, 4.0);

  const double lcnc = worst_residual_um(t, linuxcnc_model(linuxcnc_comp_file(t, "test")));
  const double lcnc_b = worst_residual_um(y_play, linuxcnc_backlash_model(0.004));
  const auto sin = sinumerik_outputs(props, {});
  const double b_x_mm = t.mean_lost_motion_um() * 1e-3;
  const double sinu = worst_residual_um(t, sinumerik_model(*find(sin, "sinumerik/AX_EEC.INI"), "X1", b_x_mm));
  const auto fan = fanuc_outputs(props, {{10.0}, 1.0, 0.0, 0});
  const double fanu = worst_residual_um(
      t, fanuc_model(*find(fan, "fanuc/parameters.txt"), *find(fan, "fanuc/pitch_error_table.txt"), 1.0));
  const auto hei = heidenhain_outputs(props, {});
  const double heid = worst_residual_um(t, heidenhain_model(*find(hei, "heidenhain/X.COM")));
  std::printf(
      "residual after applying each export to the deviations: LinuxCNC COMP_FILE %.2g um, BACKLASH %.2g um, SINUMERIK "
      "%.2g um, "
      "FANUC %.2g um (1 um detection unit), HEIDENHAIN %.2g um\n",
      lcnc, lcnc_b, sinu, fanu, heid);
  EXPECT_LT(lcnc, 1e-3);  // 0.1 nm printed
  EXPECT_LT(lcnc_b, 1e-3);
  EXPECT_LT(sinu, 1e-3);        // 1 nm printed
  EXPECT_LE(fanu, 0.5 + 1e-9);  // half a detection unit
  EXPECT_LT(heid, 1e-3);
  // And the opposite sign in any of them would leave twice the deviation.
  EXPECT_GT(
      worst_residual_um(t, [&](double x, Approach a) { return -linuxcnc_model(linuxcnc_comp_file(t, "t"))(x, a); }),
      10.0);
}

TEST(CompExports, ABacklashWithoutTableIsLinuxCncsBacklashKeyAndTheOthersMachineData) {
  const auto props = sample_proposals();
  const auto sin = sinumerik_outputs(props, {});
  EXPECT_NE(find(sin, "sinumerik/backlash.txt")->find("$MA_BACKLASH[0,Y1]=0.004000"), std::string::npos);
  const auto fan = fanuc_outputs(props, {{10.0}, 1.0, 0.0, 0});
  EXPECT_NE(find(fan, "fanuc/parameters.txt")->find("N01851A1P6A2P4"), std::string::npos)
      << *find(fan, "fanuc/parameters.txt");
  const auto hei = heidenhain_outputs(props, {});
  EXPECT_NE(find(hei, "heidenhain/backlash.txt")->find("Y: MP_backLash = 0.004000"), std::string::npos);
}

// The exact text of every format: a change shows up here. EICAL_UPDATE_GOLDEN=1 rewrites
// the files (then read the diff).
TEST(CompExports, GoldenFiles) {
  const auto props = sample_proposals();
  std::vector<OutputFile> all;
  std::vector<JointSettings> joints = {{0, 'x', std::nullopt, std::string("eical_joint0.comp"), {"x: test table"}},
                                       {1, 'y', 0.004, std::nullopt, {"y: test backlash"}}};
  all.push_back(
      {"linuxcnc/eical_joint0.comp", linuxcnc_comp_file(sample_table(), "eical comp, joint 0 (x): test table")});
  all.push_back({"linuxcnc/eical-comp.ini", linuxcnc_ini_snippet(joints, "# eical comp test\n")});
  for (auto& f : sinumerik_outputs(props, {})) all.push_back(f);
  for (auto& f : fanuc_outputs(props, {{10.0}, 1.0, 0.0, 0})) all.push_back(f);
  for (auto& f : heidenhain_outputs(props, {})) all.push_back(f);
  const fs::path golden = fs::path(EICAL_SOURCE_DIR) / "tests/tools/golden/comp";
  const bool update = std::getenv("EICAL_UPDATE_GOLDEN") && std::string(std::getenv("EICAL_UPDATE_GOLDEN")) == "1";
  for (const auto& f : all) {
    const fs::path p = golden / f.path;
    if (update) {
      fs::create_directories(p.parent_path());
      std::ofstream(p, std::ios::binary) << f.text;
      continue;
    }
    std::ifstream is(p, std::ios::binary);
    ASSERT_TRUE(is) << p << " missing (EICAL_UPDATE_GOLDEN=1 writes it)";
    const std::string expected{std::istreambuf_iterator<char>(is), std::istreambuf_iterator<char>()};
    EXPECT_EQ(f.text, expected) << f.path;
  }
}

TEST(CompExports, MergingKeepsTheMachinesIniAndRefusesWhatItCannotMap) {
  const std::string ini =
      "[KINS]\nKINEMATICS = trivkins coordinates=XZ\n[JOINT_0]\nBACKLASH = 0.01\n# keep me\n[JOINT_1]\nFERROR = 1\n";
  const auto map = joint_map(ini, "lathe.ini");
  EXPECT_EQ(map.at('x'), 0);
  EXPECT_EQ(map.at('z'), 1);
  EXPECT_EQ(map.count('y'), 0u);
  const std::string merged = merge_linuxcnc_ini(ini, "lathe.ini", {{1, 'z', 0.003, std::nullopt, {"z"}}});
  EXPECT_NE(merged.find("# keep me"), std::string::npos);
  EXPECT_NE(merged.find("[JOINT_1]\nFERROR = 1\n# eical comp (z):\n# z\nBACKLASH = 0.0030000"), std::string::npos)
      << merged;
  EXPECT_THROW((void)joint_map("[KINS]\nKINEMATICS = 5axiskins\n", "m.ini"), dsp::InputError);
  EXPECT_THROW((void)merge_linuxcnc_ini("[JOINT_0]\n[JOINT_0]\n", "m.ini", {{0, 'x', 0.001, std::nullopt, {}}}),
               dsp::InputError);
  EXPECT_THROW((void)linuxcnc_ini_snippet({{0, 'x', 0.001, std::string("a.comp"), {}}}, ""),
               dsp::InputError);  // BACKLASH and COMP_FILE
}

TEST(CompExports, AtMost256PointsForLinuxCnc) {
  AxisTable t;
  for (int i = 0; i < 300; ++i) t.pos_mm.push_back(i), t.forward_um.push_back(0), t.reverse_um.push_back(0);
  EXPECT_THROW((void)linuxcnc_comp_file(t, "x"), dsp::InputError);
}

}  // namespace
}  // namespace eical::tools::comp
