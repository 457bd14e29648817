// Every TOML file and CSV header of the drivers (run.toml and samples.csv, scenarios, sensor
// calibrations, program files, the importers' CSVs) refuses a name it does not know, naming
// the file, the line and the name (issue 32: a misspelt k1_v_per_g in run.toml left the
// sensitivity at its default, silently), and passes over the extension namespace ext_
// (docs/run-files.md). The valid inputs come from eical's own writers where it has one.
// The command line's readers: tests/tools/unknown_names_test.cpp; eicald's configuration:
// tests/daemon/daemon_config_test.cpp.
#include "tests/support/unknown_names.hpp"
#include "drivers/config/scenario_file.hpp"
#include "drivers/config/sensor_calibration.hpp"
#include "drivers/import/capture_files.hpp"
#include "drivers/run_io/run_reader.hpp"
#include "drivers/run_io/run_writer.hpp"
#include "drivers/setpoint/program_catalog.hpp"

namespace eical {
namespace {

using namespace eical::test_support;

// A small recorded run as eical writes it, with a [[psd]] strip, a reference and a
// set-point origin, so that run.toml has every table the reader knows.
void write_small_run(const fs::path& dir) {
  dsp::Run r;
  r.meta.id = "strict-0001";
  r.meta.created = "2026-11-28T10:00:00Z";
  r.meta.program.kind = eical::dsp::ProgramKind::circle;
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

Case run_case(const std::string& name, const std::string& after, const std::string& prefix = "") {
  return {"run_toml_" + name,
          "run/run.toml",
          [](const fs::path& d) { write_small_run(d / "run"); },
          [](const fs::path& d) { (void)drivers::read_run(d / "run"); },
          false,
          after,
          prefix};
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
  for (const char* after : {"seed = ", "[program]", "[reference]", "[servo.x]", "[effects.\"machine.backlash\"]"})
    c.push_back(toml_case(std::string("scenario_") + (after[0] == '[' ? "table" : "root") + std::to_string(c.size()),
                          "s.toml", scenario, read_scenario, after));
  // [effects] itself: its keys are effect names, an unknown one is refused as such.
  c.push_back({"scenario_effects", "s.toml", scenario, read_scenario, false, "", "[effects]"});
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
