#pragma once
// `eical simulate --export klipper FILE | shaketune FILE | csv PREFIX`: the simulated run as another system
// would have recorded it, with jittered stamps and lost batches (drivers/import
// capture_export), and the export's truth appended to the run's truth.toml ([export]).
#include "sim/regimes/capture_clock.hpp"
#include "sim/scenario.hpp"

#include <optional>
#include <string>

namespace eical::tools {

// The systems whose recordings --export writes: Klipper's raw capture, Shake&Tune's .stdata,
// an accelerometer CSV with an NC trace.
enum class ExportFormat { klipper, shaketune, csv };
const char* export_format_name(ExportFormat format);        // as --export takes it and truth.toml records it
ExportFormat parse_export_format(const std::string& name);  // InputError naming the three

struct ExportRequest {
  ExportFormat format = ExportFormat::klipper;
  std::string target;                    // klipper, shaketune: the file; csv: PREFIX-accel.csv, PREFIX-nc.{ngc.txt|csv}
  std::string nc_format = "halsampler";  // csv: "halsampler" | "csv"
  double servo_period_s = 0.001;
  double nc_offset_s = 1234.5678;  // NC clock at the run's t = 0
  sim::CaptureClock clock;
};

// Simulates the scenario with the capture's sampling, writes the run to `out` and the
// export files; returns the line to print.
std::string simulate_with_export(const sim::Scenario& scenario, const ExportRequest& request, const std::string& out,
                                 bool gzip, bool overwrite);

}  // namespace eical::tools
