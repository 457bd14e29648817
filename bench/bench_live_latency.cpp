// Sample → Live latency of eicald's service: the sim source paced at 10 kHz (its
// acquisition thread stamps each block on CLOCK_MONOTONIC when it has it), the service's
// DSP thread and HMI publisher as in production, and a DDS subscriber in another thread
// (its own participant, loopback) that takes every Live and computes now − acquired_ns.
// Optional busy threads load the other core. Prints p50/p99/max and the overrun count;
// `--json` prints one JSON object instead (for the test that asserts a loose bound).
//
//   bench_live_latency [--duration 600] [--load 1] [--rt-priority 80] [--json]
#include "daemon/service/service.hpp"
#include "daemon/system/realtime.hpp"
#include "drivers/dds/bus.hpp"
#include "drivers/dds/domain_claim.hpp"
#include "drivers/source/stamped_source.hpp"

#include <unistd.h>
#include <CLI/CLI.hpp>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <thread>
#include <vector>

int main(int argc, char** argv) {
  CLI::App app{"sample -> Live publication latency of the eicald service (sim source, 10 kHz, DDS loopback)"};
  double duration_s = 600.0;
  int load_threads = 0, rt_priority = 0, domain = 0;
  bool json = false;
  app.add_option("--duration", duration_s, "seconds to measure")->default_val(600.0)->check(CLI::PositiveNumber);
  app.add_option("--load", load_threads, "busy threads loading the other core(s)")->default_val(0);
  app.add_option(
         "--rt-priority", rt_priority,
         "SCHED_FIFO priority of eicald's DSP thread (publisher 10 below); the subscriber, as a real-time HMI would, "
         "runs 20 below (0 = all normal)")
      ->default_val(0);
  app.add_option("--domain", domain, "DDS domain (default: derived from the pid)");
  app.add_flag("--json", json, "print one JSON object");
  CLI11_PARSE(app, argc, argv);
  if (domain == 0) domain = eical::drivers::dds::claim_free_domain();

  const auto dir = std::filesystem::temp_directory_path() / ("eical-bench-latency-" + std::to_string(::getpid()));
  eical::daemon::DaemonConfig c;
  c.source.pacing = "realtime";        // 10 kHz on the sample clock, like the DAQ
  c.source.sim_repeat_program = true;  // measurements keep running: the DSP thread integrates
  c.source.sim_repeats = 2;
  c.source.sim_idle_s = 1.0;
  c.recording.dir = dir;
  c.recording.gzip = false;
  c.realtime.sched_fifo_priority = rt_priority;
  c.realtime.mlockall = rt_priority > 0;
  c.dds.domain_id = domain;
  c.dds.config_uri = "file://" EICAL_SOURCE_DIR_BENCH "/config/cyclonedds-loopback.xml";
  ::setenv("CYCLONEDDS_URI", c.dds.config_uri.c_str(), 1);

  std::atomic<bool> stop{false}, load_stop{false};
  std::vector<std::thread> load;
  for (int i = 0; i < load_threads; ++i)
    load.emplace_back([&] {
      volatile double x = 1.0;
      while (!load_stop.load(std::memory_order_relaxed)) x = x * 1.0000001 + 1e-9;  // pure CPU, no syscalls
    });

  std::atomic<std::uint64_t> overruns{0}, frames{0};
  std::thread service([&] {
    try {
      eical::daemon::Service(c).run(stop, [&](const eical::daemon::ServiceStatus& s) {
        overruns = s.overruns;
        frames = s.frames;
      });
    } catch (const std::exception& e) {
      std::fprintf(stderr, "service: %s\n", e.what());
      std::exit(2);
    }
  });

  std::vector<double> latency_ms;
  latency_ms.reserve(static_cast<std::size_t>(duration_s * 150));
  std::uint64_t unstamped = 0, overruns_at_start = 0;
  {
    // Set before the participant exists, so Cyclone's receive threads inherit it.
    if (rt_priority > 20) (void)eical::daemon::make_this_thread_realtime(rt_priority - 20, "bench-hmi");
    eical::drivers::dds::Bus hmi(domain, eical::drivers::dds::Role::hmi);
    // Discovery first: the measurement starts with the first Live received.
    const auto first_deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
    bool started = false;
    while (!started && std::chrono::steady_clock::now() < first_deadline)
      started = hmi.take_live(std::chrono::milliseconds(200)).has_value();
    if (!started) {
      std::fprintf(stderr, "no Live sample within 30 s\n");
      std::exit(2);
    }
    overruns_at_start = overruns.load();
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                                            std::chrono::duration<double>(duration_s));
    while (std::chrono::steady_clock::now() < end) {
      const auto l = hmi.take_live(std::chrono::milliseconds(200));
      if (!l) continue;
      const std::int64_t now = eical::drivers::monotonic_ns();
      if (l->acquired_ns <= 0) {
        ++unstamped;
        continue;
      }
      latency_ms.push_back(static_cast<double>(now - l->acquired_ns) * 1e-6);
    }
  }
  stop = true;
  service.join();  // its last status carries the final counters
  const std::uint64_t overruns_measured = overruns.load() - overruns_at_start;
  load_stop = true;
  for (auto& t : load) t.join();
  std::filesystem::remove_all(dir);

  if (latency_ms.empty()) {
    std::fprintf(stderr, "no Live samples measured\n");
    return 2;
  }
  std::sort(latency_ms.begin(), latency_ms.end());
  auto pct = [&](double p) {
    return latency_ms[std::min(latency_ms.size() - 1,
                               static_cast<std::size_t>(p * static_cast<double>(latency_ms.size())))];
  };
  const double p50 = pct(0.50), p99 = pct(0.99), pmax = latency_ms.back();
  if (json) {
    std::printf(
        "{\"duration_s\": %.1f, \"load_threads\": %d, \"rt_priority\": %d, \"samples\": %zu, \"unstamped\": %llu, "
        "\"p50_ms\": %.4f, \"p99_ms\": %.4f, \"max_ms\": %.4f, \"overruns\": %llu, \"frames\": %llu}\n",
        duration_s, load_threads, rt_priority, latency_ms.size(), static_cast<unsigned long long>(unstamped), p50, p99,
        pmax, static_cast<unsigned long long>(overruns_measured), static_cast<unsigned long long>(frames.load()));
  } else {
    std::printf("sample -> Live latency over %.0f s at 10 kHz, %d busy thread(s), SCHED_FIFO %d: %zu Live samples\n",
                duration_s, load_threads, rt_priority, latency_ms.size());
    std::printf("  p50 %.3f ms   p99 %.3f ms   max %.3f ms   overruns %llu   frames %llu\n", p50, p99, pmax,
                static_cast<unsigned long long>(overruns_measured), static_cast<unsigned long long>(frames.load()));
  }
  return 0;
}
