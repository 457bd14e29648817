#pragma once
// One program on a headless LinuxCNC driving the real eicald (integrations/linuxcnc kit):
// eical gen-nc writes the program, eicald (`[source] kind = "linuxcnc"`) simulates the
// machine from the servo stream, LinuxCNC's user M-codes trigger it over DDS, and the
// Result comes back over DDS; the recorded run stays in the scratch directory.
// Needs LinuxCNC (scripts/deps.sh test installs linuxcnc-uspace); without it the tests
// fail saying so. EICAL_SKIP_LINUXCNC=1 skips them on purpose.
#include "../hil/child_process.hpp"
#include "../hil/hil_support.hpp"
#include "drivers/run_io/run_reader.hpp"

#include <nlohmann/json.hpp>

#include <cstdio>
#include <cstdlib>

namespace eical::test {

inline std::string kit() { return EICAL_SOURCE_DIR "/integrations/linuxcnc"; }

inline void require_linuxcnc() {
  if (const char* s = std::getenv("EICAL_SKIP_LINUXCNC"); s && std::string(s) == "1")
    GTEST_SKIP() << "EICAL_SKIP_LINUXCNC=1";
  if (std::system("command -v linuxcnc >/dev/null 2>&1") != 0)
    FAIL() << "LinuxCNC is not installed: run scripts/deps.sh test (installs linuxcnc-uspace), or set "
              "EICAL_SKIP_LINUXCNC=1";
}

struct LcncProgram {
  std::string tag;                    // scratch directory name
  std::vector<std::string> gen_args;  // eical gen-nc arguments (program and its options)
  std::string machine;                // the simulated machine: scenario TOML without [program]
  fs::path config;                    // LinuxCNC configuration folder (copied); default: the kit
  std::string ini = "eical-sim3.ini";
  std::string drive = "command";  // eicald [source.linuxcnc] drive: command or feedback
};

struct TriggerTiming {
  int code;
  double after_stop_ms, before_move_ms;  // from the last set-point change, to the next
};

struct ProgramOutcome {
  nlohmann::json result;
  fs::path run_dir;  // the recorded eical-run/1
  std::vector<TriggerTiming> triggers;
  std::vector<std::pair<int, std::int64_t>> markers;  // M-code marker → sample (from eicald's log)
  std::vector<std::pair<int, std::int64_t>> trigger_samples;
  std::string stream_stats;
};

inline std::vector<TriggerTiming> trigger_timing(const dsp::Run& run) {
  const auto& f = run.frames;
  auto moved = [&](std::size_t n) {
    for (int a = 0; a < 3; ++a)
      if (f[n].cmd_mm[a] != f[n - 1].cmd_mm[a]) return true;
    return false;
  };
  const double ms = 1e3 / run.meta.acquisition.fs_hz;
  std::vector<TriggerTiming> out;
  for (std::size_t n = 1; n < f.size(); ++n) {
    if (f[n].trigger == 0) continue;
    std::size_t a = n, b = n + 1;
    while (a > 1 && !moved(a)) --a;
    while (b < f.size() && !moved(b)) ++b;
    const double none = std::nan("");
    out.push_back({f[n].trigger, a > 1 ? static_cast<double>(n - a) * ms : none,
                   b < f.size() ? static_cast<double>(b - n) * ms : none});
  }
  return out;
}

inline ProgramOutcome run_program(const LcncProgram& prog) {
  ProgramOutcome o;
  const fs::path dir = scratch_dir("lcnc-" + prog.tag);
  const fs::path cfg = dir / "cfg", rec = dir / "rec", fifo = dir / "servo.fifo";
  fs::copy(prog.config.empty() ? fs::path(kit()) : prog.config, cfg, fs::copy_options::recursive);
  fs::create_directories(cfg / "nc");
  fs::create_directories(rec);
  const int domain = hil_domain(static_cast<int>(prog.tag.size()) * 13);
  const std::string uri = "file://" EICAL_SOURCE_DIR "/config/cyclonedds-loopback.xml";
  {
    std::ofstream env(cfg / "eical.env");
    env << "EICAL=" EICAL_CLI "\nEICAL_FIFO=" << fifo.string() << "\nEICAL_DOMAIN=" << domain
        << "\nEICAL_DDS_CONFIG=" << uri << "\nEICAL_MARK=1\n";
  }
  std::vector<std::string> gen = {EICAL_CLI, "gen-nc"};
  gen.insert(gen.end(), prog.gen_args.begin(), prog.gen_args.end());
  gen.insert(gen.end(), {"-o", (cfg / "nc/prog.ngc").string(), "--meta", (dir / "program.toml").string()});
  int rc = -1;
  EXPECT_TRUE(run_capture(gen, 20s, &rc) && rc == 0) << "eical gen-nc failed";
  {
    std::ofstream sc(dir / "machine.toml");
    sc << "format = \"eical-scenario/1\"\nname = \"lcnc-" << prog.tag << "\"\n"
       << prog.machine << "\n"
       << slurp(dir / "program.toml");  // a scenario file names its program
  }
  {
    std::ofstream c(dir / "eicald.toml");
    c << "[source]\nkind = \"linuxcnc\"\nretry_s = 0.5\n[source.linuxcnc]\nfifo = \"" << fifo.string()
      << "\"\nprogram_file = \"" << (dir / "program.toml").string() << "\"\nscenario_file = \""
      << (dir / "machine.toml").string() << "\"\ndrive = \"" << prog.drive
      << "\"\nconnect_timeout_s = 10\n[triggers]\ninputs = [\"dds\"]\n[dds]\ndomain_id = " << domain
      << "\nconfig_uri = \"" << uri << "\"\n[recording]\ndir = \"" << rec.string()
      << "\"\ngzip = false\n[limits]\nmax_measurement_s = 300.0\n"
      << "[realtime]\nsched_fifo_priority = 0\nmlockall = false\n";
  }
  NcOnBus hmi(domain);
  ChildProcess eicald({EICALD_BIN, "--config", (dir / "eicald.toml").string()}, (dir / "eicald.log").string());
  // eicald creates the pipe the kit writes; LinuxCNC starts once it exists.
  for (int i = 0; i < 100 && !fs::is_fifo(fifo); ++i) std::this_thread::sleep_for(50ms);
  if (!fs::is_fifo(fifo) || !eicald.running()) {
    ADD_FAILURE() << "eicald did not start:\n" << slurp(dir / "eicald.log");
    return o;
  }
  ChildProcess lcnc({"/bin/bash", (cfg / "run-headless").string(), (cfg / prog.ini).string(),
                     (cfg / "nc/prog.ngc").string(), "400", "1.5"},
                    (dir / "run-headless.log").string());
  auto lrc = lcnc.wait_exit(450s);
  if (!lrc) {
    // SIGTERM: run-headless's trap shuts LinuxCNC down cleanly (never SIGKILL it).
    lcnc.signal(SIGTERM);
    lrc = lcnc.wait_exit(40s);
  }
  EXPECT_EQ(lrc.value_or(-1), 0) << "LinuxCNC run failed:\n"
                                 << slurp(dir / "run-headless.log") << slurp(cfg / "linuxcnc.log");
  std::optional<drivers::dds::ResultMsg> r;
  const auto end = std::chrono::steady_clock::now() + 90s;
  while (!r && std::chrono::steady_clock::now() < end) r = hmi.bus().take_result(500ms);
  eicald.signal(SIGTERM);
  EXPECT_TRUE(eicald.wait_exit(20s)) << "eicald did not stop";
  const std::string log = slurp(dir / "eicald.log");
  EXPECT_TRUE(r) << "no Result over DDS; eicald log:\n"
                 << log << "\nrun-headless:\n"
                 << slurp(dir / "run-headless.log");
  if (!r) return o;
  o.result = nlohmann::json::parse(r->json);
  // "M-code marker <code·100000 + pid> at servo cycle <n> = sample <k>" (no std::regex: GCC 12
  // warns falsely inside it under -O2 with sanitizers).
  for (std::size_t at = log.find("M-code marker "); at != std::string::npos; at = log.find("M-code marker ", at + 1)) {
    long long id = 0, cycle = 0, sample = 0;
    if (std::sscanf(log.c_str() + at, "M-code marker %lld at servo cycle %lld = sample %lld", &id, &cycle, &sample) ==
        3)
      o.markers.emplace_back(static_cast<int>(id / 100000), sample);
  }
  if (log.find("<6>linuxcnc: ") != std::string::npos) {
    const auto q = log.rfind("<6>linuxcnc: ");
    o.stream_stats = log.substr(q, log.find('\n', q) - q);
  }
  for (const auto& d : fs::directory_iterator(rec)) {
    if (!fs::is_directory(d.path())) continue;
    o.run_dir = d.path();
    const dsp::Run run = drivers::read_run(d.path());
    o.triggers = trigger_timing(run);
    for (const auto& f : run.frames)
      if (f.trigger) o.trigger_samples.emplace_back(f.trigger, f.sample_index);
  }
  return o;
}

}  // namespace eical::test
