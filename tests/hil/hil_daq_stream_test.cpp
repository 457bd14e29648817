// Hardware in the loop through the real decode path: a simulated circle run is streamed
// into the real eicald as a DAQ would send it (the USB DAQ's wire protocol, FrameEncoder,
// into the named pipe of [source] kind = "daq_stream", paced at 10 kHz) while the NC's
// set-point comes from elsewhere:
//   (a) LinuxCNC's servo stream (the test writes the run's set-point as the kit's
//       halsampler lines, 1 kHz, bursts every 10 ms, its own cycle numbers, 3.7 ms off the
//       DAQ clock); the triggers on the DAQ's trigger channel;
//   (b) the program M101 P7 names (programs/7.toml, the gen-nc file), reconstructed by
//       eical's interpolator; the triggers over DDS as `eical trigger` sends them, and the
//       NC dwelling 37 ms longer after M101 than the program says (an M-code's dead time).
// Each recorded run's set-point equals the simulated one, and the circle result equals
// `eical analyze` of the simulated run within the tolerance below.
#include "child_process.hpp"
#include "drivers/run_io/run_reader.hpp"
#include "drivers/run_io/run_writer.hpp"
#include "drivers/setpoint/program_catalog.hpp"
#include "drivers/source/stamped_source.hpp"
#include "drivers/usb_daq/frame_encoder.hpp"
#include "dsp/analysis/analyze_run.hpp"
#include "hil_support.hpp"
#include "sim/simulate.hpp"

#include <fcntl.h>
#include <sys/stat.h>

#include <nlohmann/json.hpp>

#include <cmath>
#include <csignal>
#include <sstream>

namespace eical::test {
namespace {

constexpr double kDaqFs = 10000.0;
constexpr std::int64_t kServoCycle0 = 734512;  // LinuxCNC's cycle count at the servo stream's start
constexpr double kServoOffsetS = 0.0037;       // servo cycle kServoCycle0 happens 3.7 ms after DAQ sample 0
constexpr std::int64_t kDeadTimeFrames = 370;  // (b): the NC rests 37 ms longer after M101

// The simulated run as the machine produced it, and the frames the DAQ streams: rest before
// and after (eicald starts, the pre-trigger window fills), optionally extra rest after M101.
struct Stream {
  dsp::Run sim;                      // the simulated run (written for `eical analyze`)
  std::vector<dsp::Frame> frames;    // what the DAQ sends, indices from 0
  std::vector<std::int64_t> origin;  // frame k shows the simulated run's frame origin[k]
};

Stream make_stream(const fs::path& program_file, std::int64_t dead_time_frames) {
  Stream s;
  sim::Scenario sc = sim::circle_scenario(10.0, 2500.0, 2, "ccw", 3);
  sc.meta.program = drivers::read_program_file(program_file);
  s.sim = sim::simulate(sc);
  const auto lead = static_cast<std::int64_t>(2.5 * kDaqFs), tail = static_cast<std::int64_t>(1.5 * kDaqFs);
  auto add = [&](std::int64_t j, bool trigger) {
    dsp::Frame f = s.sim.frames[static_cast<std::size_t>(
        std::clamp<std::int64_t>(j, 0, static_cast<std::int64_t>(s.sim.frames.size()) - 1))];
    f.sample_index = static_cast<std::int64_t>(s.frames.size());
    if (!trigger) f.trigger = 0;
    for (double& c : f.cmd_mm) c = 0.0;  // a DAQ knows no set-point
    for (double& r : f.ref_mm) r = std::nan("");
    s.frames.push_back(f);
    s.origin.push_back(j);
  };
  for (std::int64_t k = 0; k < lead; ++k) add(k % 2000, false);  // the run's own rest, before its M101
  for (std::int64_t j = 0; j < static_cast<std::int64_t>(s.sim.frames.size()); ++j) {
    add(j, true);
    // The extra rest is the run's own rest again (a held frame would be a stuck channel to
    // eicald's channel health: a real sensor at rest still shows its noise).
    if (s.sim.frames[static_cast<std::size_t>(j)].trigger == 101)
      for (std::int64_t k = 0; k < dead_time_frames; ++k) add(k % 2000, false);
  }
  for (std::int64_t k = 0; k < tail; ++k) add(static_cast<std::int64_t>(s.sim.frames.size()) - 1, false);
  return s;
}

// eicald's configuration for the DAQ stream with `setpoint` (a TOML block).
fs::path write_daq_config(const fs::path& dir, int domain, const std::string& inputs, const std::string& setpoint) {
  const fs::path file = dir / "eicald.toml";
  std::ofstream os(file);
  os << "[source]\nkind = \"daq_stream\"\nretry_s = 0.5\n"
     << "[source.daq_stream]\npath = \"" << (dir / "daq.fifo").string()
     << "\"\nconnect_timeout_s = 30.0\nstall_timeout_s = 2.0\n"
     << setpoint << "\n"
     << "[triggers]\ninputs = " << inputs << "\n"
     << "[dds]\ndomain_id = " << domain
     << "\nconfig_uri = \"file://" EICAL_SOURCE_DIR "/config/cyclonedds-loopback.xml\"\n"
     << "[recording]\ndir = \"" << (dir / "runs").string() << "\"\ngzip = false\n"
     << "[limits]\nmax_measurement_s = 60.0\n"
     << "[realtime]\nsched_fifo_priority = 0\nmlockall = false\n";
  return file;
}

// The DAQ: encodes the frames into the wire protocol and writes them into eicald's pipe at
// 10 kHz (a packet of 32 samples when its last sample is due). t0_ns: sample 0's time.
class DaqDevice {
 public:
  DaqDevice(const fs::path& fifo, const std::vector<dsp::Frame>& frames)
      : ignore_sigpipe_(std::signal(SIGPIPE, SIG_IGN)), thread_([this, fifo, &frames] { run(fifo, frames); }) {}
  ~DaqDevice() {
    stop_ = true;
    thread_.join();
  }
  [[nodiscard]] std::int64_t t0_ns() const { return t0_ns_.load(); }
  [[nodiscard]] bool done() const { return done_.load(); }

 private:
  void run(const fs::path& fifo, const std::vector<dsp::Frame>& frames) {
    for (int i = 0; i < 3000 && !fs::is_fifo(fifo) && !stop_; ++i) std::this_thread::sleep_for(10ms);
    const int fd = ::open(fifo.c_str(), O_WRONLY);  // eicald holds the read end
    if (fd < 0) return;
    drivers::usb_daq::FrameEncoder enc(0, 32);
    std::vector<std::uint8_t> bytes;
    const std::int64_t t0 = drivers::monotonic_ns() + 20'000'000;
    t0_ns_ = t0;
    for (std::size_t i = 0; i < frames.size() && !stop_; i += 32) {
      const std::size_t n = std::min<std::size_t>(32, frames.size() - i);
      sleep_until_ns(t0 + static_cast<std::int64_t>(static_cast<double>(i + n - 1) * 1e9 / kDaqFs));
      bytes.clear();
      enc.encode(std::span<const dsp::Frame>(frames).subspan(i, n), bytes);
      if (::write(fd, bytes.data(), bytes.size()) < 0) break;
    }
    done_ = true;
    // Keep streaming rest (the DAQ does not stop) until the test is done.
    dsp::Frame rest = frames.back();
    std::int64_t index = rest.sample_index;
    while (!stop_) {
      std::vector<dsp::Frame> block(32, rest);
      for (auto& f : block) f.sample_index = ++index, f.trigger = 0;
      sleep_until_ns(t0 + static_cast<std::int64_t>(static_cast<double>(index) * 1e9 / kDaqFs));
      bytes.clear();
      enc.encode(block, bytes);
      if (::write(fd, bytes.data(), bytes.size()) < 0) break;
    }
    ::close(fd);
  }
  // eicald closes the pipes when it stops: the writers see EPIPE, not a fatal SIGPIPE.
  void (*ignore_sigpipe_)(int);
  std::atomic<bool> stop_{false}, done_{false};
  std::atomic<std::int64_t> t0_ns_{0};
  std::thread thread_;
};

// LinuxCNC's side of the servo stream: the set-point of the frames as halsampler lines.
class ServoStreamWriter {
 public:
  ServoStreamWriter(const fs::path& fifo, const Stream& s, const DaqDevice& daq)
      : thread_([this, fifo, &s, &daq] { run(fifo, s, daq); }) {}
  ~ServoStreamWriter() {
    stop_ = true;
    thread_.join();
  }

 private:
  void run(const fs::path& fifo, const Stream& s, const DaqDevice& daq) {
    for (int i = 0; i < 3000 && !(fs::is_fifo(fifo) && daq.t0_ns() != 0) && !stop_; ++i)
      std::this_thread::sleep_for(10ms);
    const int fd = ::open(fifo.c_str(), O_WRONLY);
    if (fd < 0) return;
    const std::int64_t t0 = daq.t0_ns();
    // The commanded position at DAQ time t (s): the simulated run's set-point of that frame.
    auto cmd_at = [&](double t, int a) {
      const double x = std::clamp(t * kDaqFs, 0.0, static_cast<double>(s.frames.size() - 2));
      const auto k = static_cast<std::size_t>(x);
      const auto& f0 = s.sim.frames[static_cast<std::size_t>(s.origin[k])];
      const auto& f1 = s.sim.frames[static_cast<std::size_t>(s.origin[k + 1])];
      return f0.cmd_mm[a] + (f1.cmd_mm[a] - f0.cmd_mm[a]) * (x - static_cast<double>(k));
    };
    // Cycles from now on (the machine ran before; the stream starts when eicald listens).
    std::int64_t k = std::max<std::int64_t>(
        0, static_cast<std::int64_t>((static_cast<double>(drivers::monotonic_ns() - t0) * 1e-9 - kServoOffsetS) * 1e3));
    for (; !stop_; k += 10) {
      sleep_until_ns(t0 + static_cast<std::int64_t>((kServoOffsetS + static_cast<double>(k + 9) * 1e-3) * 1e9));
      std::string burst;
      for (std::int64_t j = k; j < k + 10; ++j) {
        const double t = kServoOffsetS + static_cast<double>(j) * 1e-3;
        char line[200];
        std::snprintf(line, sizeof line, "%lld %.6f %.6f %.6f %.6f %.6f %.6f 0\n",
                      static_cast<long long>(kServoCycle0 + j), cmd_at(t, 0), cmd_at(t, 1), cmd_at(t, 2), cmd_at(t, 0),
                      cmd_at(t, 1), cmd_at(t, 2));
        burst += line;
      }
      if (::write(fd, burst.data(), burst.size()) < 0) break;
    }
    ::close(fd);
  }
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

struct Outcome {
  fs::path run_dir;
  nlohmann::json result, reference;
};

// The recorded run of eicald, its result, and `eical analyze` of the simulated run.
Outcome collect(const fs::path& dir, const Stream& s, ChildProcess& eicald) {
  Outcome o;
  const auto end = std::chrono::steady_clock::now() + 120s;
  while (o.run_dir.empty() && std::chrono::steady_clock::now() < end) {
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(dir / "runs", ec))
      if (fs::exists(e.path() / "result.json")) o.run_dir = e.path();
    std::this_thread::sleep_for(200ms);
  }
  eicald.signal(SIGTERM);
  EXPECT_EQ(eicald.wait_exit(30s), std::optional<int>(0)) << slurp(dir / "eicald.log");
  if (o.run_dir.empty()) return o;
  std::this_thread::sleep_for(300ms);
  o.result = nlohmann::json::parse(slurp(o.run_dir / "result.json"));
  drivers::write_run(s.sim, dir / "simulated", {.gzip = false, .overwrite = true});
  int rc = -1;
  // --no-suggest: no simulated variants; the exit status is the verdict's (0 ok, 2 degraded,
  // 3 not measurable), 1 an error.
  const auto analyzed =
      run_capture({EICAL_CLI, "analyze", (dir / "simulated").string(), "--json", "--no-suggest"}, 120s, &rc);
  const bool ok = analyzed && (rc == 0 || rc == 2 || rc == 3);
  EXPECT_TRUE(ok) << "eical analyze failed with " << rc;
  if (ok) o.reference = nlohmann::json::parse(*analyzed);
  return o;
}

// The recorded set-point against the simulated one, frame by frame: the largest
// difference (µm) while the machine moves.
double setpoint_error_um(const dsp::Run& run, const Stream& s) {
  double worst = 0.0;
  for (const auto& f : run.frames) {
    const auto k = static_cast<std::size_t>(f.sample_index);
    if (k >= s.origin.size()) continue;
    const auto& sim = s.sim.frames[static_cast<std::size_t>(s.origin[k])];
    for (int a = 0; a < 3; ++a) worst = std::max(worst, std::abs(f.cmd_mm[a] - sim.cmd_mm[a]) * 1e3);
  }
  return worst;
}

// The tolerance on G and the mean radius deviation: the result's expanded uncertainty when
// it states one (eical-result/1 uncertainty_k2, coverage k = 2), else the same from the
// run's noise: twice the standard deviation of the figure over the simulated run's sensor
// noise (the same program, machine and sensors; five noise seeds). The two evaluations
// integrate the very same accelerometer samples and differ only in the set-point's
// windows (the rest window that estimates the bias, the revolutions' ends); how much a
// noise realisation moves the figure bounds how much such a window change can.
struct Tolerance {
  double g_um = 0.0, r_um = 0.0;
  std::string basis;
};

Tolerance tolerance_from_noise(const fs::path& program_file) {
  std::vector<double> g, r;
  for (std::uint64_t seed : {3, 11, 12, 13, 14}) {
    sim::Scenario sc = sim::circle_scenario(10.0, 2500.0, 2, "ccw", seed);
    sc.meta.program = drivers::read_program_file(program_file);
    const dsp::Analysis a = dsp::analyze_run(sim::simulate(sc));
    if (!a.circle) continue;
    g.push_back(a.circle->circular_deviation_G_um), r.push_back(a.circle->radius_mean_deviation_um);
  }
  auto two_sigma = [](const std::vector<double>& v) {
    double m = 0.0, ss = 0.0;
    for (double x : v) m += x;
    m /= static_cast<double>(v.size());
    for (double x : v) ss += (x - m) * (x - m);
    return 2.0 * std::sqrt(ss / static_cast<double>(v.size() - 1));
  };
  EXPECT_EQ(g.size(), 5u);
  return {two_sigma(g), two_sigma(r), "2 sigma over 5 noise seeds"};
}

Tolerance tolerance_of(const nlohmann::json& result, const fs::path& program_file) {
  const auto& u = result["uncertainty_k2"];
  const char* g = "circle.circular_deviation_G_um";
  const char* r = "circle.radius_mean_deviation_um";
  if (u.is_object() && u.contains(g) && u[g].is_number() && u.contains(r) && u[r].is_number())
    return {u[g].get<double>(), u[r].get<double>(), "uncertainty_k2 of the result"};
  return tolerance_from_noise(program_file);
}

void expect_same_circle(const Outcome& o, const fs::path& program_file) {
  ASSERT_TRUE(o.result["circle"].is_object()) << o.result["quality"].dump();
  ASSERT_TRUE(o.reference["circle"].is_object()) << o.reference["quality"].dump();
  EXPECT_EQ(o.result["circle"]["revolutions"], o.reference["circle"]["revolutions"]);
  const Tolerance t = tolerance_of(o.result, program_file);
  for (const char* key : {"circular_deviation_G_um", "radius_mean_deviation_um"}) {
    const double got = o.result["circle"][key].get<double>(), want = o.reference["circle"][key].get<double>();
    const double tol = std::string(key) == "circular_deviation_G_um" ? t.g_um : t.r_um;
    EXPECT_NEAR(got, want, tol) << key;
    std::printf(
        "  %s: eicald %.4f um, eical analyze of the simulated run %.4f um, difference %+.4f um (tolerance %.3f um, "
        "%s)\n",
        key, got, want, got - want, tol, t.basis.c_str());
  }
}

TEST(HilDaqStream, ServoStreamSetPointBesideTheDaq) {
  const fs::path dir = scratch_dir("daq-servo");
  int rc = -1;
  fs::create_directories(dir / "programs");
  ASSERT_TRUE(run_capture({EICAL_CLI, "gen-nc", "circle", "--radius", "10", "--feed", "2500", "--repeats", "2", "-o",
                           (dir / "circle.ngc").string(), "--meta", (dir / "programs" / "7.toml").string()},
                          30s, &rc));
  ASSERT_EQ(rc, 0);
  const Stream s = make_stream(dir / "programs" / "7.toml", 0);
  const int domain = hil_domain(6);
  // The triggers on the DAQ's input carry no P word: the program evaluated is the default.
  const fs::path cfg =
      write_daq_config(dir, domain, "[\"frame\"]",
                       "[setpoint]\nsource = \"servo_stream\"\n[setpoint.servo_stream]\nfifo = \"" +
                           (dir / "servo.fifo").string() + "\"\nhold_ms = 300.0\n[setpoint.program]\ndirectory = \"" +
                           (dir / "programs").string() + "\"\ndefault_program = 7\n");
  ChildProcess eicald({EICALD_BIN, "--config", cfg.string()}, (dir / "eicald.log").string());
  Outcome o;
  {
    DaqDevice daq(dir / "daq.fifo", s.frames);
    ServoStreamWriter linuxcnc(dir / "servo.fifo", s, daq);
    o = collect(dir, s, eicald);
  }
  ASSERT_FALSE(o.run_dir.empty()) << "no recording; log:\n" << slurp(dir / "eicald.log");
  const auto run = drivers::read_run(o.run_dir);
  ASSERT_TRUE(run.meta.setpoint) << "run.toml has no [setpoint]";
  const auto& sp = *run.meta.setpoint;
  EXPECT_EQ(sp.source, "servo_stream");
  EXPECT_EQ(sp.program_number, 7);
  EXPECT_EQ(run.meta.program.kind, eical::dsp::ProgramKind::circle);
  const double true_cycle = static_cast<double>(kServoCycle0) +
                            (static_cast<double>(run.frames.front().sample_index) / kDaqFs - kServoOffsetS) * 1e3;
  const double err_um = setpoint_error_um(run, s);
  std::printf(
      "(a) servo stream: servo cycle at the first sample %.3f (true %.3f, %+.3f ms); set-point within %.2f um of the "
      "simulated one;\n"
      "    cross-correlation: measured lags the set-point by %+.3f ms, correlation %.4f, residual %.2f %%\n",
      sp.servo_cycle_at_first_sample, true_cycle, (sp.servo_cycle_at_first_sample - true_cycle), err_um, sp.lag_s * 1e3,
      sp.correlation, sp.residual_ratio * 100.0);
  EXPECT_NEAR(sp.servo_cycle_at_first_sample, true_cycle, 0.5) << "the clocks' offset within 0.5 ms";
  EXPECT_LT(err_um, 25.0);
  EXPECT_NEAR(sp.lag_s, 0.0, 5e-4);
  EXPECT_LT(sp.residual_ratio, 0.2);
  EXPECT_FALSE(o.result["quality"]["degraded"].get<bool>()) << o.result["quality"]["flags"].dump();
  expect_same_circle(o, dir / "programs" / "7.toml");
  fs::remove_all(dir);
}

TEST(HilDaqStream, ProgramSetPointNamedByM101BesideTheDaq) {
  const fs::path dir = scratch_dir("daq-program");
  int rc = -1;
  fs::create_directories(dir / "programs");
  ASSERT_TRUE(run_capture({EICAL_CLI, "gen-nc", "circle", "--radius", "10", "--feed", "2500", "--repeats", "2", "-o",
                           (dir / "circle.ngc").string(), "--meta", (dir / "programs" / "7.toml").string()},
                          30s, &rc));
  ASSERT_EQ(rc, 0);
  const Stream s = make_stream(dir / "programs" / "7.toml", kDeadTimeFrames);
  const int domain = hil_domain(7);
  const fs::path cfg = write_daq_config(
      dir, domain, "[\"dds\"]",
      "[setpoint]\nsource = \"program\"\n[setpoint.program]\ndirectory = \"" + (dir / "programs").string() + "\"\n");
  ChildProcess eicald({EICALD_BIN, "--config", cfg.string()}, (dir / "eicald.log").string());
  Outcome o;
  {
    DaqDevice daq(dir / "daq.fifo", s.frames);
    NcOnBus nc(domain);
    ASSERT_TRUE(nc.handshake(40s)) << "eicald did not answer on DDS; log:\n" << slurp(dir / "eicald.log");
    while (daq.t0_ns() == 0) std::this_thread::sleep_for(10ms);
    // The NC's M-codes at their frames' times (sent 300 ms ahead, as eical trigger stamps
    // the moment the M-code ran); M101 names program 7.
    for (const auto& f : s.frames) {
      if (f.trigger == 0) continue;
      const std::int64_t due =
          daq.t0_ns() + static_cast<std::int64_t>(static_cast<double>(f.sample_index) * 1e9 / kDaqFs);
      sleep_until_ns(due - 300'000'000);
      const auto reply = nc.trigger_reply(f.trigger, due, f.trigger == 101 ? 7.0 : std::nan(""));
      ASSERT_TRUE(reply && reply->ok) << "M" << f.trigger << ": " << (reply ? reply->message : std::string("no reply"));
    }
    o = collect(dir, s, eicald);
  }
  ASSERT_FALSE(o.run_dir.empty()) << "no recording; log:\n" << slurp(dir / "eicald.log");
  const auto run = drivers::read_run(o.run_dir);
  ASSERT_TRUE(run.meta.setpoint) << "run.toml has no [setpoint]";
  const auto& sp = *run.meta.setpoint;
  EXPECT_EQ(sp.source, "program");
  EXPECT_EQ(sp.program_number, 7);
  EXPECT_EQ(run.meta.program.kind, eical::dsp::ProgramKind::circle);
  EXPECT_FALSE(run.meta.program.gcode.empty()) << "the program travels with the run";
  const double err_um = setpoint_error_um(run, s);
  std::printf(
      "(b) program 7: marks offset %+.3f ms, after the cross-correlation %+.3f ms (the NC's 37 ms dead time after "
      "M101: %+.3f ms "
      "expected from the marks); %d motion block(s); set-point within %.2f um of the simulated one;\n"
      "    measured lags the set-point by %+.3f ms, correlation %.4f, residual %.2f %%\n",
      sp.marks_offset_s * 1e3, sp.offset_s * 1e3, static_cast<double>(kDeadTimeFrames) / kDaqFs * 1e3, sp.blocks,
      err_um, sp.lag_s * 1e3, sp.correlation, sp.residual_ratio * 100.0);
  // The motion starts 37 ms later than the M101 mark says: the cross-correlation finds it.
  EXPECT_NEAR((sp.offset_s - sp.marks_offset_s) * 1e3, static_cast<double>(kDeadTimeFrames) / kDaqFs * 1e3, 8.0)
      << "the 37 ms within the DDS mark's latency";
  EXPECT_LT(err_um, 25.0);
  EXPECT_NEAR(sp.lag_s, 0.0, 5e-4);
  EXPECT_LT(sp.residual_ratio, 0.2);
  EXPECT_FALSE(o.result["quality"]["degraded"].get<bool>()) << o.result["quality"]["flags"].dump();
  expect_same_circle(o, dir / "programs" / "7.toml");
  fs::remove_all(dir);
}

}  // namespace
}  // namespace eical::test
