#pragma once
// eicald's configuration (config/eicald.toml documents every key). Read strictly: unknown
// or mistyped keys are errors naming file, line and key, so a typo never silently falls
// back to a default on a machine tool.
#include "drivers/source/fault_source.hpp"
#include "drivers/source/sim_factory.hpp"
#include "dsp/core/run_meta.hpp"

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace eical::daemon {

// [source.linuxcnc]: LinuxCNC's servo-rate positions drive the simulated machine and
// sensors (integrations/linuxcnc streams them into `fifo`).
struct LinuxcncConfig {
  std::filesystem::path fifo = "/run/eical/linuxcnc-servo.fifo";
  std::filesystem::path program_file;  // eical gen-nc --meta: what LinuxCNC runs (the evaluation)
  std::optional<dsp::Program> program_loaded;
  std::filesystem::path scenario_file;          // eical-scenario/1: the machine and sensor truth (optional)
  double servo_rate_hz = 1000.0;                // [EMCMOT]SERVO_PERIOD
  double block_ms = 200.0, history_ms = 300.0;  // simulation windows
  std::string drive = "command";                // command | feedback: which positions move the machine
  double connect_timeout_s = 10.0, stall_timeout_s = 2.0;
  double hold_ms = 1000.0;  // frame latency: must exceed the M-code → DDS trigger time
  std::uint64_t seed = 1;
};

// [source.daq_stream]: the DAQ's wire protocol from a named pipe or a Unix socket (a DAQ
// bridge, or the device simulator of the hardware-in-the-loop tests).
struct DaqStreamConfig {
  std::filesystem::path path = "/run/eical/daq.stream";
  double connect_timeout_s = 5.0;
  double stall_timeout_s = 1.0;
};

struct SourceConfig {
  std::string kind = "sim";          // sim | replay | usb_daq | daq_stream | linuxcnc
  std::string pacing = "realtime";   // realtime | free_running (sim, replay)
  std::filesystem::path replay_run;  // replay: an eical-run/1 directory
  // sim: the calibration program the simulated NC runs; its M101/102/103 reach the
  // daemon on the DAQ trigger channel, as a PLC wired to the DAQ's trigger input would.
  dsp::ProgramKind sim_program = dsp::ProgramKind::circle;  // circle | step
  double sim_radius_mm = 10.0;
  double sim_feed_mm_min = 2500.0;
  int sim_repeats = 5;
  std::uint64_t sim_seed = 1;
  double sim_idle_s = 2.0;         // rest between repetitions of the program
  bool sim_repeat_program = true;  // run the program again after each idle time
  // The [program] table written by `eical gen-nc ... --meta FILE` (kind, geometry and the
  // G-code the simulated NC runs); replaces program/radius/feed/repeats when set.
  std::filesystem::path sim_program_file;
  std::optional<dsp::Program> sim_program_loaded;  // read from sim_program_file at load
  double retry_s = 2.0;                            // a source that failed mid-run is reopened after this
  drivers::FaultPlan fault;                        // [source.fault]: injected faults (tests, commissioning)
  std::string usb_id = "1d50:6161";                // usb_daq: vendor:product
  LinuxcncConfig linuxcnc;                         // [source.linuxcnc]
  DaqStreamConfig daq_stream;                      // [source.daq_stream]
  [[nodiscard]] bool is_daq() const { return kind == "usb_daq" || kind == "daq_stream"; }
};

// [setpoint]: where the NC set-point comes from when the frames come from a DAQ (which
// measures accelerations only). "servo_stream": LinuxCNC's servo-rate commanded positions
// (integrations/linuxcnc) combined with the frames on the DAQ clock; "program": the program
// M101's P word names, reconstructed by eical's interpolator and aligned at evaluation.
struct SetPointConfig {
  std::string source = "none";  // none | servo_stream | program
  // [setpoint.servo_stream]
  std::filesystem::path servo_fifo = "/run/eical/linuxcnc-servo.fifo";
  double servo_rate_hz = 1000.0;
  double hold_ms = 1000.0;  // frames wait this long: servo lines (~10 ms) and DDS triggers (~0.75 s) arrive first
  // [setpoint.program]
  std::filesystem::path program_dir = "/etc/eical/programs";  // <number>.toml from eical gen-nc --meta
  int default_program = -1;  // used when M101 carries no P word (frame, GPIO triggers); -1 = none
  bool mcode_stops = false;  // the NC stops at every M-code (LinuxCNC)
  double max_lag_s = 0.3;    // cross-correlation search around the marks
  double a_max_mm_s2 = 2000.0, j_max_mm_s3 = 50000.0, rapid_mm_min = 10000.0;  // the NC's path limits
};

struct TriggerConfig {
  // Which inputs may deliver M101/M102/M103: "frame" (DAQ trigger channel), "dds"
  // (Command topic, used by `eical trigger`), "gpio", "can".
  std::vector<std::string> inputs = {"frame", "dds"};
  std::string gpio_chip = "gpiochip0";
  std::vector<int> gpio_lines = {17, 27, 22};  // lines for M101, M102, M103 (rising edge)
  double gpio_debounce_ms = 5.0;               // a second edge of one line within this time is contact bounce
  std::string can_interface = "can0";
  std::uint32_t can_id = 0x1E0;  // NC trigger frame id
};

struct DdsConfig {
  int domain_id = 0;
  std::string config_uri;  // Cyclone DDS XML; empty = CYCLONEDDS_URI / built-in default
  double live_rate_hz = 100.0;
  double status_rate_hz = 1.0;
  std::size_t trace_max_points = 20000;  // Trace topic: longer traces are decimated
};

struct RecordingConfig {
  std::filesystem::path dir = "/var/lib/eical/runs";
  bool gzip = true;
};

// [history]: every evaluated result also goes into the calibration history (eical history
// list | trend | compare). Off unless the config turns it on (the installed eicald.toml does).
struct HistoryConfig {
  bool enabled = false;
  std::string db = "/var/lib/eical/history.db";                      // SQLite file, or postgresql://...
  std::filesystem::path spool_dir = "/var/lib/eical/history-spool";  // results waiting for the store
  double retry_s = 30.0;                                             // an unavailable store is tried again
};

struct Limits {
  std::size_t ring_capacity_frames = 65536;  // 6.5 s at 10 kHz: rides out a stalled DSP (or recording) thread
  double max_measurement_s = 600.0;          // longest measurement recorded (written as measured, not held)
  double temp_min_c = 5.0;
  double temp_max_c = 45.0;
  std::uint64_t max_lost_frames = 0;  // more lost frames than this → result flagged degraded
};

struct RealtimeConfig {
  int sched_fifo_priority = 80;  // 0 = normal scheduling
  bool mlockall = true;
};

struct DaemonConfig {
  std::string file;  // where it was read from (for messages)
  SourceConfig source;
  SetPointConfig setpoint;
  TriggerConfig triggers;
  DdsConfig dds;
  RecordingConfig recording;
  HistoryConfig history;
  Limits limits;
  RealtimeConfig realtime;
  dsp::Acquisition acquisition;
  dsp::Site site;
  dsp::MachineLayout machine;
  dsp::WorkEnvelope envelope;              // [envelope]: the simulated program must stay within it; runs carry it
  dsp::SensorSpec sensors[2];              // data-sheet values, table and head
  std::filesystem::path calibration_file;  // identified calibration (optional, overrides)
  std::vector<dsp::PsdSpec> psd;
};

// Throws dsp::InputError "file:line: section.key: reason" on any problem.
DaemonConfig load_daemon_config(const std::filesystem::path& file);

// What the service believes about its hardware, as a run's metadata: DAQ, site, machine,
// envelope, sensors and strips; the program is unknown until a set-point source names one
// (freeform).
dsp::RunMeta hardware_meta(const DaemonConfig& c);

// The simulated machine of [source.sim] (the backend when no hardware is present).
drivers::SimMachine sim_machine(const DaemonConfig& c);

}  // namespace eical::daemon
