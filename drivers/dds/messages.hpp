#pragma once
// Plain C++ forms of the DDS topics (drivers/dds/eical.idl): the rest of eical never
// touches generated C types or dds_* calls.
#include "drivers/dds/status_counters.hpp"
#include "dsp/core/float_limits.hpp"

#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

namespace eical::drivers::dds {

struct StatusMsg {
  std::string daemon, state, fault;
  std::uint64_t frames = 0, overruns = 0, frames_lost = 0, measurements = 0, results = 0;
  float temp_table_c = kNaN, temp_head_c = kNaN;
  std::int64_t time_ns = 0;
  std::int64_t sample_index = 0, sample_time_ns = 0;  // DAQ clock ↔ CLOCK_MONOTONIC
  StatusCounters counters;                            // every counter of the service (status_counters.hpp)
};

struct LiveMsg {
  std::string daemon;
  std::int64_t sample_index = 0;
  std::array<double, 3> pos_mm{}, vel_mm_s{};
  bool integrating = false;
  std::int64_t acquired_ns = 0;  // CLOCK_MONOTONIC when the acquisition thread had the sample
};

struct ResultMsg {
  std::string machine, program_id, program;  // key: machine + program_id (the run id)
  bool degraded = false;
  double circular_deviation_G_um = kNaN, radius_mean_deviation_um = kNaN;
  std::uint64_t results = 0;  // the daemon's result count, this one included
  std::string json;
  std::string measured_at, run_path, software_version, sensor_calibration;  // provenance (history)
};

struct TraceMsg {
  std::string program_id, program, x_name, y_name;
  std::vector<double> x, y;
  std::vector<std::int32_t> series;
  std::vector<bool> cw;  // empty when the program has no direction per point
  std::uint32_t decimation = 1;
};

struct CommandMsg {
  std::string sender;
  std::uint32_t request_id = 0;
  std::string action;  // trigger | arm | abort | reset
  std::int32_t code = 0;
  double p = kNaN, q = kNaN;
  std::int64_t time_ns = 0;
};

struct ReplyMsg {
  std::string sender;
  std::uint32_t request_id = 0;
  bool ok = false;
  std::string message, state;
};

}  // namespace eical::drivers::dds
