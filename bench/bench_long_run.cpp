// Long recordings (issue 17, item 7): peak memory and speed of `eical analyze` and of
// eicald's evaluation for circular tests of 1, 10 and 30 minutes at 10 kHz (R150, both
// directions, repeated; F1000 — the 1-minute run at F2000, since one revolution each way
// at F1000 takes two minutes). Each analysis runs in a child process of its own, so its
// peak resident set is its own. The acceptance: at most 150 MB for a 10-minute recording
// and at least 50x real time.
//
//   eical analyze   the command as a user runs it (the run read as it streams), with eical
//                   plan's suggestion of a measurable test when the test is not measurable
//   eical analyze --no-suggest   the same without the suggestion
//   eicald eval     eicald's own code: the recording thread (RecordingWriter) writes the
//                   run's frames as the DSP thread hands them over (RecordingStream, fed
//                   here as fast as it drains), then the evaluation thread (Evaluator) names
//                   the run, renames it into place and analyses it from disk. Its time is
//                   from the recording's end to its result.json (what follows the
//                   measurement); its peak RSS is the process's over recording and
//                   evaluation, "evaluation" the peak after the recording's end.
//
// Prints one line per run and analysis: minutes of data, samples, wall and CPU seconds,
// x real time (wall and CPU), peak RSS in MB and the verdict (a result was written).
//
//   bench_long_run [--minutes 1,10,30] [--dir DIR] [--keep] [--no-daemon]
#include "drivers/run_io/run_reader.hpp"
#include "drivers/run_io/run_stream.hpp"
#include "dsp/core/float_limits.hpp"
#ifdef EICAL_BENCH_DAEMON
#include "daemon/service/evaluator.hpp"
#include "daemon/service/recording_handoff.hpp"
#include "daemon/service/recording_stream.hpp"
#endif

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>
#include <CLI/CLI.hpp>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace fs = std::filesystem;

namespace {

struct Usage {
  double wall_s = 0, user_s = 0, sys_s = 0, peak_mb = 0;
  int status = 0;
};

double seconds(const timeval& t) { return static_cast<double>(t.tv_sec) + static_cast<double>(t.tv_usec) * 1e-6; }

// Runs `child` in a forked process (stdout to /dev/null when quiet); its rusage.
template <class F>
Usage in_child(F&& child, bool quiet = true) {
  std::fflush(stdout);  // else the child's freopen() writes the parent's buffered lines again
  const auto t0 = std::chrono::steady_clock::now();
  const pid_t pid = ::fork();
  if (pid == 0) {
    if (quiet) {
      std::FILE* null = std::freopen("/dev/null", "w", stdout);
      (void)null;
    }
    int code = 1;
    try {
      code = child();
    } catch (const std::exception& e) {
      std::fprintf(stderr, "bench_long_run: %s\n", e.what());
    }
    std::fflush(stdout);
    ::_exit(code);
  }
  Usage u;
  rusage ru{};
  ::wait4(pid, &u.status, 0, &ru);
  u.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  u.user_s = seconds(ru.ru_utime), u.sys_s = seconds(ru.ru_stime);
  u.peak_mb = static_cast<double>(ru.ru_maxrss) / 1024.0;
  return u;
}

int run_command(const std::vector<std::string>& args) {
  std::vector<char*> argv;
  for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  ::execv(argv[0], argv.data());
  std::perror("execv");
  return 127;
}

// eical analyze's exit status: 0, 2 and 3 come with a result (verdict ok, degraded, not
// measurable: docs/command-line.md); anything else failed.
std::string outcome(int status) {
  if (!WIFEXITED(status)) return "  FAILED (killed)";
  switch (WEXITSTATUS(status)) {
    case 0: return "  verdict ok";
    case 2: return "  verdict degraded";
    case 3: return "  verdict not measurable";
    default: return "  FAILED (exit " + std::to_string(WEXITSTATUS(status)) + ")";
  }
}

void print(const char* what, double minutes, std::size_t samples, const Usage& u, const std::string& extra = "") {
  const double data_s = minutes * 60.0;
  std::printf(
      "%-28s %5.1f min %9zu samples  wall %7.2f s (%6.1fx real time)  cpu %7.2f s (%6.1fx)  peak RSS %6.1f MB%s%s\n",
      what, minutes, samples, u.wall_s, data_s / u.wall_s, u.user_s + u.sys_s, data_s / (u.user_s + u.sys_s), u.peak_mb,
      extra.c_str(), outcome(u.status).c_str());
  std::fflush(stdout);
}

// The simulated circle of about `minutes` (made once; kept with --keep).
fs::path simulated_run(const fs::path& base, const std::string& eical, double minutes) {
  // R150 both directions: F1000 turns a revolution in 56.5 s, so repeats of both cover
  // about 113 s each; the minute-long run turns at F2000.
  const double feed = minutes < 2.0 ? 2000.0 : 1000.0;
  const int repeats = std::max(1, static_cast<int>(std::lround(minutes * 60.0 / (feed < 1500.0 ? 113.1 : 56.5))));
  const fs::path run =
      base / ("circle-r150-f" + std::to_string(static_cast<int>(feed)) + "-both-x" + std::to_string(repeats));
  if (fs::exists(run / "run.toml")) return run;
  const Usage s = in_child([&] {
    return run_command({eical, "simulate", "--program", "circle", "--radius", "150", "--feed",
                        std::to_string(static_cast<int>(feed)), "--direction", "both", "--repeats",
                        std::to_string(repeats), "-o", run.string(), "--overwrite"});
  });
  if (s.status != 0) throw std::runtime_error("eical simulate failed");
  return run;
}

std::size_t rows_of(const fs::path& run) {
  std::ifstream is(run / "samples.csv");
  std::string line;
  std::size_t rows = 0;
  while (std::getline(is, line)) ++rows;
  return rows > 0 ? rows - 1 : 0;
}

#ifdef EICAL_BENCH_DAEMON
// The process' peak resident size since the last reset_peak() (VmHWM), MB.
double peak_mb() {
  std::ifstream is("/proc/self/status");
  std::string line;
  while (std::getline(is, line))
    if (line.rfind("VmHWM:", 0) == 0) return std::stod(line.substr(6)) / 1024.0;
  return eical::kNaN;
}

// Resets VmHWM to the current resident size (Linux >= 4.0: clear_refs 5).
void reset_peak() { std::ofstream("/proc/self/clear_refs") << "5"; }

struct Inside {
  double eval_s = eical::kNaN, eval_cpu_s = eical::kNaN, eval_peak_mb = eical::kNaN;
  int verdict = 1;
};

// eicald's recording thread and evaluation thread over the run's frames (read as they
// stream, as a DAQ delivers them); the recording directory under `dir`.
Inside daemon_evaluation(const fs::path& run, const fs::path& dir) {
  namespace d = eical::daemon;
  eical::drivers::RunStream frames(run);
  d::DaemonConfig config;
  config.recording.dir = dir;
  d::RecordingStream stream(1 << 16);
  d::RecordingHandoff handoff(stream);
  d::Evaluator evaluator(config, frames.header().meta, {}, stream, handoff, {});
  stream.begin();
  frames.replay([&](const eical::dsp::Frame& f) {
    while (stream.queued() > stream.capacity() / 2) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    (void)stream.frame(f);
  });
  reset_peak();
  rusage a{}, b{};
  ::getrusage(RUSAGE_SELF, &a);
  const auto t0 = std::chrono::steady_clock::now();
  stream.end(d::RecordingNotes{});
  while (evaluator.status().results == 0 && evaluator.status().fault.find("recording") == std::string::npos)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  Inside in;
  in.eval_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  ::getrusage(RUSAGE_SELF, &b);
  in.eval_cpu_s = seconds(b.ru_utime) + seconds(b.ru_stime) - seconds(a.ru_utime) - seconds(a.ru_stime);
  in.eval_peak_mb = peak_mb();
  evaluator.finish();
  const d::EvaluationStatus st = evaluator.status();
  if (st.results == 1) {
    std::ifstream is(st.last_result);
    const std::string text((std::istreambuf_iterator<char>(is)), std::istreambuf_iterator<char>());
    in.verdict = text.find("\"not_measurable\"") != std::string::npos ? 3
                 : text.find("\"degraded\"") != std::string::npos     ? 2
                                                                      : 0;
  }
  return in;
}

void bench_daemon(const fs::path& run, const fs::path& base, double data_min, std::size_t rows, bool keep) {
  const fs::path dir = base / "eicald-runs";
  fs::remove_all(dir);
  int fd[2];
  if (::pipe(fd) != 0) return;
  const Usage whole = in_child([&] {
    ::close(fd[0]);
    const Inside in = daemon_evaluation(run, dir);
    const ssize_t w = ::write(fd[1], &in, sizeof in);
    return w == sizeof in ? 0 : 1;
  });
  ::close(fd[1]);
  Inside in;
  if (::read(fd[0], &in, sizeof in) != sizeof in) in = Inside{};
  ::close(fd[0]);
  Usage eval = whole;  // the evaluation's own time; the peak is the process's
  eval.wall_s = in.eval_s, eval.user_s = in.eval_cpu_s, eval.sys_s = 0.0;
  if (whole.status == 0) eval.status = in.verdict << 8;  // the verdict, as eical analyze's exit status
  char extra[96];
  std::snprintf(extra, sizeof extra, "  (evaluation %.1f MB)", in.eval_peak_mb);
  print("eicald eval", data_min, rows, eval, extra);
  if (!keep) fs::remove_all(dir);
}
#endif

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"peak memory and speed of eical analyze and eicald's evaluation for long circular tests"};
  std::vector<double> minutes{1, 10, 30};
  std::string dir_opt;
  bool keep = false, no_daemon = false;
  app.add_option("--minutes", minutes, "lengths to measure (about: whole revolutions)")->delimiter(',');
  app.add_option("--dir", dir_opt, "where the simulated runs go (default: /var/tmp; 0.8 GB a 10-minute run)");
  app.add_flag("--keep", keep, "keep the runs (and reuse them next time)");
  app.add_flag("--no-daemon", no_daemon, "eical analyze only");
  CLI11_PARSE(app, argc, argv);
  const fs::path base = dir_opt.empty() ? fs::path("/var/tmp") / "eical-bench-long-run" : fs::path(dir_opt);
  fs::create_directories(base);
  const std::string eical = EICAL_CLI_BENCH;
  std::printf("machine: %ld online cores, load average %s", ::sysconf(_SC_NPROCESSORS_ONLN), [] {
    std::ifstream is("/proc/loadavg");
    static std::string l;
    std::getline(is, l);
    l += "\n";
    return l.c_str();
  }());
  for (const double m : minutes) {
    fs::path run;
    try {
      run = simulated_run(base, eical, m);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "bench_long_run: %s\n", e.what());
      return 1;
    }
    const auto meta = eical::drivers::read_run_meta(run / "run.toml");
    const std::size_t rows = rows_of(run);
    const double data_min = static_cast<double>(rows) / meta.acquisition.fs_hz / 60.0;
    const Usage cli = in_child([&] { return run_command({eical, "analyze", run.string(), "--json"}); });
    print("eical analyze", data_min, rows, cli);
    const Usage bare = in_child([&] {
      return run_command({eical, "analyze", run.string(), "--json", "--no-suggest"});
    });
    print("eical analyze --no-suggest", data_min, rows, bare);
#ifdef EICAL_BENCH_DAEMON
    if (!no_daemon) bench_daemon(run, base, data_min, rows, keep);
#else
    (void)no_daemon;
#endif
    if (!keep) fs::remove_all(run);
  }
  return 0;
}
