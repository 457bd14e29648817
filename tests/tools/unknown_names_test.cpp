// The command line's TOML files and CSV tables (tolerances, the volumetric model, error
// curves, angle series, points, ISO 230-2 deviations) refuse a name they do not know with the
// file, the line and the name, and pass over the extension namespace ext_
// (docs/run-files.md). The drivers' readers: tests/drivers/unknown_names_test.cpp.
#include "tests/support/unknown_names.hpp"
#include "tools/io/csv_inputs.hpp"
#include "tools/io/positioning_readers.hpp"
#include "tools/io/volumetric_model_file.hpp"
#include "tools/report/tolerances.hpp"

namespace eical {
namespace {

using namespace eical::test_support;

std::string deviation_csv() {
  std::string s = "target_mm,run,direction,deviation_um\n";
  for (const char* t : {"0", "50"})
    for (const char* run : {"1", "2"})
      for (const char* d : {"up", "down"}) s += std::string(t) + "," + run + "," + d + ",1.5\n";
  return s;
}

const fs::path kSource = EICAL_SOURCE_DIR;

std::vector<Case> cases() {
  std::vector<Case> c;
  const auto tolerances = [](const fs::path& d) {
    write(
        d / "t.toml",
        "format = \"eical-tolerances/1\"\n\n[header]\nmachine = \"m\"\n\n[circle]\nG_um = 5.0\n\n[positioning]\nA_um = "
        "10.0\n");
  };
  const auto read_tolerances = [](const fs::path& d) { (void)tools::report::read_tolerances(d / "t.toml"); };
  for (const char* after : {"format = ", "[header]", "[circle]", "[positioning]"})
    c.push_back(toml_case("tolerances_" + std::to_string(c.size()), "t.toml", tolerances, read_tolerances, after));
  const auto volumetric = [](const fs::path& d) {
    fs::copy_file(kSource / "config" / "examples" / "volumetric-example.toml", d / "v.toml");
  };
  const auto read_volumetric = [](const fs::path& d) { (void)tools::read_volumetric_model((d / "v.toml").string()); };
  for (const char* after : {"format = ", "[axes]", "[squareness]", "[[component]]"})
    c.push_back(
        toml_case("volumetric_model_" + std::to_string(c.size()), "v.toml", volumetric, read_volumetric, after));

  c.push_back(csv_case(
      "error_curve_csv", "c.csv", [](const fs::path& d) { write(d / "c.csv", "pos_mm,error_um\n0,0\n50,1\n100,2\n"); },
      [](const fs::path& d) { (void)tools::read_error_curve_csv((d / "c.csv").string()); }));
  c.push_back(csv_case(
      "angle_series_csv", "a.csv",
      [](const fs::path& d) { write(d / "a.csv", "angle_deg,deviation_arcsec,series\n0,0,a\n90,1,a\n180,0.5,a\n"); },
      [](const fs::path& d) { (void)tools::read_angle_series_csv((d / "a.csv").string()); }));
  c.push_back(csv_case(
      "volumetric_points_csv", "p.csv", [](const fs::path& d) { write(d / "p.csv", "x,y,z,xp,yp,zp\n0,0,0,0,0,0\n"); },
      [](const fs::path& d) { (void)tools::read_volumetric_points_csv((d / "p.csv").string()); }));
  c.push_back(csv_case(
      "deviation_csv", "dev.csv", [](const fs::path& d) { write(d / "dev.csv", deviation_csv()); },
      [](const fs::path& d) { (void)tools::read_deviation_csv((d / "dev.csv").string()); }));
  return c;
}

INSTANTIATE_TEST_SUITE_P(EveryReader, UnknownName, ::testing::ValuesIn(cases()),
                         [](const ::testing::TestParamInfo<Case>& i) { return i.param.name; });

}  // namespace
}  // namespace eical
