// Every TOML file and CSV header eical reads refuses a name it does not know, naming the
// file, the line and the name (issue 32: a misspelt k1_v_per_g in run.toml left the
// sensitivity at its default, silently), and passes over the extension namespace ext_
// (docs/run-files.md). The valid inputs are written by eical's own writers where it has one.
// eicald's configuration has the same test in tests/daemon (its reader is not in this suite).
#include "drivers/config/scenario_file.hpp"
#include "drivers/config/sensor_calibration.hpp"
#include "drivers/import/capture_files.hpp"
#include "drivers/run_io/run_reader.hpp"
#include "drivers/run_io/run_writer.hpp"
#include "drivers/setpoint/program_catalog.hpp"
#include "dsp/core/error.hpp"
#include "tools/io/csv_inputs.hpp"
#include "tools/io/positioning_readers.hpp"
#include "tools/io/volumetric_model_file.hpp"
#include "tools/report/tolerances.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <random>
#include <sstream>

namespace eical {
namespace {

namespace fs = std::filesystem;

std::string slurp(const fs::path& p) {
  std::ifstream is(p);
  return {std::istreambuf_iterator<char>(is), std::istreambuf_iterator<char>()};
}

void write(const fs::path& p, const std::string& text) { std::ofstream(p) << text; }

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream is(text);
  for (std::string l; std::getline(is, l);) out.push_back(l);
  return out;
}

std::string joined(const std::vector<std::string>& lines) {
  std::string out;
  for (const auto& l : lines) out += l + "\n";
  return out;
}

// A small recorded run as eical writes it, with a [[psd]] strip, a reference and a
// set-point origin, so that run.toml has every table the reader knows.
void write_small_run(const fs::path& dir) {
  dsp::Run r;
  r.meta.id = "strict-0001";
  r.meta.created = "2026-11-28T10:00:00Z";
  r.meta.program.kind = "circle";
  r.meta.program.gcode = "G90\nM101\n";
  r.meta.psd = {dsp::PsdSpec{}};
  r.meta.reference = dsp::Reference{"KGM182", {"x", "y"}};
  r.meta.setpoint = dsp::SetPointOrigin{};
  r.meta.setpoint->source = "program";
  r.channels.ref[0] = r.channels.ref[1] = true;
  r.channels.psd_count = 1;
  for (int i = 0; i < 20; ++i) {
    dsp::Frame f;
    f.sample_index = i;
    for (int c = 0; c < 6; ++c) f.accel_counts[c] = 100 * c - i;
    f.temp_c[0] = f.temp_c[1] = 21.0f;
    f.cmd_mm[0] = 0.01 * i;
    f.trigger = i == 1 ? 101 : 0;
    r.frames.push_back(f);
  }
  drivers::write_run(r, dir);
}

std::string deviation_csv() {
  std::string s = "target_mm,run,direction,deviation_um\n";
  for (const char* t : {"0", "50"})
    for (const char* run : {"1", "2"})
      for (const char* d : {"up", "down"}) s += std::string(t) + "," + run + "," + d + ",1.5\n";
  return s;
}

// One reader: where its input goes, how a valid one is made, how it is read, and where an
// unknown name is put in (TOML: a key after the first line that begins with `after`, or
// the `prefix` lines and the key at the end when `after` is empty; CSV: a last column).
struct Case {
  std::string name;
  std::string file;  // relative to the case's directory
  std::function<void(const fs::path& dir)> make;
  std::function<void(const fs::path& dir)> read;
  bool csv = false;
  std::string after;
  std::string prefix;        // TOML at the end: e.g. "[sensors]" to put the key in that table
  bool extension_ok = true;  // false: a fixed foreign format with no room for other columns
};

std::ostream& operator<<(std::ostream& os, const Case& c) { return os << c.name; }

// The input with `name` added; returns the line the name is on.
std::size_t add_name(const Case& c, const fs::path& file, const std::string& name) {
  auto lines = lines_of(slurp(file));
  std::size_t at = 0;
  if (c.csv) {
    lines[0] += "," + name;
    for (std::size_t i = 1; i < lines.size(); ++i)
      if (!lines[i].empty()) lines[i] += ",0";
    at = 1;
  } else if (c.after.empty()) {
    if (!c.prefix.empty()) lines.push_back(c.prefix);
    lines.push_back(name + " = 1");
    at = lines.size();
  } else {
    std::size_t i = 0;
    while (i < lines.size() && lines[i].rfind(c.after, 0) != 0) ++i;
    EXPECT_LT(i, lines.size()) << c.after << " is not in " << file;
    lines.insert(lines.begin() + static_cast<std::ptrdiff_t>(i + 1), name + " = 1");
    at = i + 2;
  }
  write(file, joined(lines));
  return at;
}

class UnknownName : public ::testing::TestWithParam<Case> {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("eical-unknown-" + std::to_string(std::random_device{}()));
    fs::create_directories(dir_);
    GetParam().make(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

TEST_P(UnknownName, ValidInputIsRead) { EXPECT_NO_THROW(GetParam().read(dir_)); }

TEST_P(UnknownName, IsRefusedWithFileLineAndName) {
  const Case& c = GetParam();
  const fs::path file = dir_ / c.file;
  const std::size_t line = add_name(c, file, c.csv ? "typo_col" : "typo_key");
  try {
    c.read(dir_);
    FAIL() << c.name << ": an unknown name was read without a word";
  } catch (const dsp::InputError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find(file.string() + ":" + std::to_string(line) + ":"), std::string::npos)
        << "expected " << file.string() << ":" << line << " in: " << msg;
    EXPECT_NE(msg.find(c.csv ? "typo_col" : "typo_key"), std::string::npos) << msg;
  }
}

TEST_P(UnknownName, ExtensionNamespaceIsPassedOver) {
  const Case& c = GetParam();
  if (!c.extension_ok) GTEST_SKIP() << c.name << " is a fixed foreign format";
  add_name(c, dir_ / c.file, "ext_note");
  EXPECT_NO_THROW(c.read(dir_));
}

Case run_case(const std::string& name, const std::string& after, const std::string& prefix = "") {
  return {"run_toml_" + name,
          "run/run.toml",
          [](const fs::path& d) { write_small_run(d / "run"); },
          [](const fs::path& d) { (void)drivers::read_run(d / "run"); },
          false,
          after,
          prefix};
}

Case toml_case(const std::string& name, const std::string& file, std::function<void(const fs::path&)> make,
               std::function<void(const fs::path&)> read, const std::string& after) {
  return {name, file, std::move(make), std::move(read), false, after, ""};
}

Case csv_case(const std::string& name, const std::string& file, std::function<void(const fs::path&)> make,
              std::function<void(const fs::path&)> read, bool extension_ok = true) {
  return {name, file, std::move(make), std::move(read), true, "", "", extension_ok};
}

const fs::path kSource = EICAL_SOURCE_DIR;

std::vector<Case> cases() {
  std::vector<Case> c = {
      run_case("root", "id = "),
      run_case("acquisition", "[acquisition]"),
      run_case("site", "[site]"),
      run_case("machine", "[machine]"),
      run_case("sensors", "", "[sensors]"),
      run_case("sensors_table", "[sensors.table]"),
      run_case("sensors_head", "[sensors.head]"),
      run_case("psd", "[[psd]]"),
      run_case("program", "[program]"),
      run_case("reference", "[reference]"),
      run_case("setpoint", "[setpoint]"),
      csv_case(
          "samples_csv", "run/samples.csv", [](const fs::path& d) { write_small_run(d / "run"); },
          [](const fs::path& d) { (void)drivers::read_run(d / "run"); }),
  };
  const auto scenario = [](const fs::path& d) {
    fs::copy_file(kSource / "config" / "scenarios" / "backlash-circle.toml", d / "s.toml");
  };
  const auto read_scenario = [](const fs::path& d) { (void)drivers::read_scenario_file((d / "s.toml").string()); };
  for (const char* after : {"seed = ", "[program]", "[reference]", "[servo.x]"})
    c.push_back(toml_case(std::string("scenario_") + (after[0] == '[' ? "table" : "root") + std::to_string(c.size()),
                          "s.toml", scenario, read_scenario, after));
  const auto calibration = [](const fs::path& d) {
    drivers::SensorCalibration cal;
    cal.method = "psd";
    cal.run_id = "identify-0001";
    cal.daq_group_delay_samples = 39.0;
    for (int s = 0; s < 2; ++s) cal.sensors[s] = dsp::RunMeta{}.sensors[s];
    drivers::write_sensor_calibration(cal, d / "cal.toml");
  };
  const auto read_calibration = [](const fs::path& d) {
    (void)drivers::read_sensor_calibration(d / "cal.toml", dsp::RunMeta{});
  };
  for (const char* after : {"run = ", "[acquisition]", "[sensors.table]", "[sensors.head]"})
    c.push_back(
        toml_case("sensor_calibration_" + std::to_string(c.size()), "cal.toml", calibration, read_calibration, after));
  const auto program = [](const fs::path& d) {
    write(d / "p.toml", "# program 7\n[program]\nkind = \"circle\"\nradius_mm = 10.0\ngcode = \"G90\\nM30\\n\"\n");
  };
  const auto read_program = [](const fs::path& d) { (void)drivers::read_program_file(d / "p.toml"); };
  c.push_back(toml_case("program_file_root", "p.toml", program, read_program, "# program 7"));
  c.push_back(toml_case("program_file_program", "p.toml", program, read_program, "[program]"));
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
  const drivers::StampedAccel capture{"", {0.0, 0.001, 0.002}, {{0, 0, 1}, {0, 0, 1}, {0, 0, 1}}};
  c.push_back(csv_case(
      "import_accel_csv", "accel.csv",
      [capture](const fs::path& d) { drivers::write_accel_csv(d / "accel.csv", capture, drivers::AccelUnit::g); },
      [](const fs::path& d) { (void)drivers::read_accel_csv(d / "accel.csv", {}, drivers::AccelUnit::g); }));
  c.push_back(csv_case(
      "import_nc_csv", "nc.csv",
      [](const fs::path& d) {
        drivers::write_nc_csv(d / "nc.csv", {"", {0.0, 0.001}, {Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitX()}});
      },
      [](const fs::path& d) { (void)drivers::read_nc_csv(d / "nc.csv", {}); }));
  c.push_back(csv_case(
      "klipper_capture", "raw.csv",
      [capture](const fs::path& d) { drivers::write_klipper_capture(d / "raw.csv", capture); },
      [](const fs::path& d) { (void)drivers::read_klipper_capture(d / "raw.csv"); }, false));
  return c;
}

INSTANTIATE_TEST_SUITE_P(EveryReader, UnknownName, ::testing::ValuesIn(cases()),
                         [](const ::testing::TestParamInfo<Case>& i) { return i.param.name; });

// The import's foreign CSVs may carry columns of their own: named on the command line
// (--ignore-cols) they are passed over, and a name that is not in the header is refused.
TEST(ImportCsvColumns, IgnoredColumnsAreNamedNotGuessed) {
  const fs::path dir = fs::temp_directory_path() / ("eical-ignore-" + std::to_string(std::random_device{}()));
  fs::create_directories(dir);
  write(dir / "a.csv", "time,temp_c,ax,ay,az\n0,20,0,0,1\n0.001,20,0,0,1\n");
  drivers::CsvColumns cols;
  cols.time = "time";
  cols.values = {"ax", "ay", "az"};
  std::string refused;
  try {
    (void)drivers::read_accel_csv(dir / "a.csv", cols, drivers::AccelUnit::g);
  } catch (const dsp::InputError& e) {
    refused = e.what();
  }
  EXPECT_NE(refused.find((dir / "a.csv").string() + ":1: column 'temp_c': unknown column"), std::string::npos)
      << refused;
  cols.ignored = {"temp_c"};
  EXPECT_EQ(drivers::read_accel_csv(dir / "a.csv", cols, drivers::AccelUnit::g).t_s.size(), 2u);
  cols.ignored = {"temp_C"};
  try {
    (void)drivers::read_accel_csv(dir / "a.csv", cols, drivers::AccelUnit::g);
    ADD_FAILURE() << "an ignored column that is not in the header was accepted";
  } catch (const dsp::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("'temp_C' is to be ignored, but the header has no such column"),
              std::string::npos)
        << e.what();
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace eical
