#pragma once
// Shared set-up of the hardware-in-the-loop tests: a scratch directory, an eicald config
// (sim backend, loopback DDS, triggers only over DDS), a DDS domain of the test's own,
// and the NC's side of the bus (commands sent once after a handshake, replies awaited).
#include "drivers/dds/bus.hpp"
#include "drivers/dds/domain_claim.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <random>
#include <string>
#include <thread>

namespace eical::test {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

inline fs::path scratch_dir(const std::string& tag) {
  const fs::path d = fs::temp_directory_path() / ("eical-hil-" + tag + "-" + std::to_string(std::random_device{}()));
  fs::create_directories(d);
  return d;
}

inline int hil_domain(int /*salt*/) {
  ::setenv("CYCLONEDDS_URI", "file://" EICAL_SOURCE_DIR "/config/cyclonedds-loopback.xml", 1);
  return drivers::dds::claim_free_domain();  // no other test on this host hears it
}

struct HilConfig {
  int domain = 0;
  fs::path program_file;  // [program] TOML from eical gen-nc --meta
  fs::path recording_dir;
  double idle_s = 1.0;
  std::string extra;  // more TOML (e.g. a [source.fault] table)
};

inline fs::path write_config(const fs::path& dir, const HilConfig& c) {
  const fs::path file = dir / "eicald.toml";
  std::ofstream os(file);
  os << "[source]\nkind = \"sim\"\npacing = \"realtime\"\nretry_s = 0.5\n"
     << "[source.sim]\nprogram_file = \"" << c.program_file.string() << "\"\nidle_s = " << c.idle_s
     << "\nrepeat_program = true\n"
     << c.extra << "\n"
     << "[triggers]\ninputs = [\"dds\"]\n"
     << "[dds]\ndomain_id = " << c.domain
     << "\nconfig_uri = \"file://" EICAL_SOURCE_DIR "/config/cyclonedds-loopback.xml\"\n"
     << "[recording]\ndir = \"" << c.recording_dir.string() << "\"\ngzip = false\n"
     << "[limits]\nmax_measurement_s = 60.0\n"
     << "[realtime]\nsched_fifo_priority = 0\nmlockall = false\n";
  return file;
}

// The NC on the bus. Commands are volatile and a resend could double a trigger, so the
// command path is proven first with a harmless unknown action (refused with a Reply),
// then every M-code is sent exactly once.
class NcOnBus {
 public:
  explicit NcOnBus(int domain) : bus_(domain, drivers::dds::Role::hmi) {}
  drivers::dds::Bus& bus() { return bus_; }

  bool handshake(std::chrono::milliseconds timeout) {
    const auto end = std::chrono::steady_clock::now() + timeout;
    while (std::chrono::steady_clock::now() < end) {
      drivers::dds::CommandMsg c;
      c.sender = sender_;
      c.request_id = ++id_;
      c.action = "ping";
      bus_.send(c);
      if (auto r = reply_for(c.request_id, 300ms)) return true;
    }
    return false;
  }

  // Sends M`code` (P word `p`) due at `time_ns` (CLOCK_MONOTONIC); eicald's Reply.
  std::optional<drivers::dds::ReplyMsg> trigger_reply(int code, std::int64_t time_ns, double p = std::nan("")) {
    drivers::dds::CommandMsg c;
    c.sender = sender_;
    c.request_id = ++id_;
    c.action = "trigger";
    c.code = code;
    c.p = p;
    c.time_ns = time_ns;
    if (!bus_.send(c)) return std::nullopt;
    return reply_for(c.request_id, 3000ms);
  }
  // True when eicald accepted it.
  bool trigger(int code, std::int64_t time_ns, double p = std::nan("")) {
    const auto r = trigger_reply(code, time_ns, p);
    return r && r->ok;
  }

  std::optional<drivers::dds::StatusMsg> status(std::chrono::milliseconds timeout,
                                                bool (*want)(const drivers::dds::StatusMsg&)) {
    const auto end = std::chrono::steady_clock::now() + timeout;
    while (std::chrono::steady_clock::now() < end)
      if (auto s = bus_.take_status(200ms); s && want(*s)) return s;
    return std::nullopt;
  }

 private:
  std::optional<drivers::dds::ReplyMsg> reply_for(std::uint32_t id, std::chrono::milliseconds timeout) {
    const auto end = std::chrono::steady_clock::now() + timeout;
    while (std::chrono::steady_clock::now() < end)
      if (auto r = bus_.take_reply(100ms); r && r->sender == sender_ && r->request_id == id) return r;
    return std::nullopt;
  }

  drivers::dds::Bus bus_;
  std::string sender_ = "hil-nc-" + std::to_string(::getpid());
  std::uint32_t id_ = 0;
};

inline std::int64_t now_ns() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1000000000 + ts.tv_nsec;
}

inline void sleep_until_ns(std::int64_t t_ns) {
  const std::int64_t d = t_ns - now_ns();
  if (d > 0) std::this_thread::sleep_for(std::chrono::nanoseconds(d));
}

inline std::string slurp(const fs::path& p) {
  std::ifstream is(p);
  return {std::istreambuf_iterator<char>(is), std::istreambuf_iterator<char>()};
}

}  // namespace eical::test
