#pragma once
// Recordings made by other systems, read strictly and written in their own formats (for
// `eical simulate --export` and the importers' tests):
//  * Klipper's raw accelerometer capture (ACCELEROMETER_MEASURE, TEST_RESONANCES ...
//    OUTPUT=raw_data; klippy/extras/adxl345.py AccelQueryHelper.write_to_file): an
//    optional "##<stats>" line, the header "#time,accel_x,accel_y,accel_z", then rows
//    "%.6f,%.6f,%.6f,%.6f" — print-time seconds and mm/s², axes already through Klipper's
//    axes_map;
//  * a generic accelerometer CSV (a header row; a time column and three axes);
//  * an NC trace: LinuxCNC's halsampler file as integrations/linuxcnc/eical-halsampler
//    writes it ("<sample number> Xcmd Ycmd Zcmd Xfb Yfb Zfb marker", one line per servo
//    cycle, "overrun" where samples were lost), or a CSV servo-trace export with a header.
// Every problem is an InputError "file:line: column 'name': reason" (or "file:line: reason").
#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace eical::drivers {

inline constexpr double kStandardGravity_mps2 = 9.80665;

// An accelerometer recording on its recorder's clock: stamps and the sensor axes (m/s²).
struct StampedAccel {
  std::string source;
  std::vector<double> t_s;  // strictly increasing
  std::vector<Eigen::Vector3d> accel_mps2;
};

// The NC's commanded position on the NC's clock.
struct NcTrace {
  std::string source;
  std::vector<double> t_s;  // strictly increasing
  std::vector<Eigen::Vector3d> pos_mm;
};

enum class AccelUnit { mps2, mmps2, g };
double accel_unit_in_mps2(AccelUnit unit);  // one unit of `unit` in m/s² (g: standard gravity)

// Which CSV columns hold what: names from the header, or "" for "by position" (time in
// the first column, the three values in the next three). Time in seconds × time_scale_s.
// Every column of the header is read, listed in `ignored`, or begins with ext_ (the extension
// namespace, docs/run-files.md); any other is refused by name, so a column the user meant to
// read is never dropped unseen.
struct CsvColumns {
  std::string time;
  std::array<std::string, 3> values;
  double time_scale_s = 1.0;
  std::vector<std::string> ignored{};  // columns of the file that are deliberately not read
};

StampedAccel read_klipper_capture(const std::filesystem::path& file);
void write_klipper_capture(const std::filesystem::path& file, const StampedAccel& capture);

StampedAccel read_accel_csv(const std::filesystem::path& file, const CsvColumns& columns, AccelUnit unit);
// Header "t,ax,ay,az", seconds and `unit`.
void write_accel_csv(const std::filesystem::path& file, const StampedAccel& capture, AccelUnit unit);

// Time = sample number × servo_period_s (the servo thread's period, [EMCMOT]SERVO_PERIOD).
NcTrace read_halsampler(const std::filesystem::path& file, double servo_period_s);
// Lines numbered first_number, first_number + 1, ... (trace.t_s is ignored: the trace
// must be on the servo grid); feedback written equal to the command, marker 0.
void write_halsampler(const std::filesystem::path& file, const NcTrace& trace, std::int64_t first_number);

NcTrace read_nc_csv(const std::filesystem::path& file, const CsvColumns& columns);
// Header "t,x,y,z", seconds and mm.
void write_nc_csv(const std::filesystem::path& file, const NcTrace& trace);

}  // namespace eical::drivers
