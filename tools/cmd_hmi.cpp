// eical hmi / eical trigger: the reference HMI on the DDS bus. `hmi` prints eicald's
// Status and every Result and Trace it receives (a late HMI still gets the last Result and
// Trace per program: transient-local) and can save the traces as CSV; `trigger` sends an M-code (101 tare + start, 102
// segment, 103 stop) as an NC user M-function would, and waits for the daemon's Reply.
#include "dsp/core/float_limits.hpp"
#include "tools/commands.hpp"

#if EICAL_HAVE_DDS
#include "drivers/dds/bus.hpp"
#include "drivers/results/resolved.hpp"
#include "dsp/core/frame.hpp"

#include <nlohmann/json.hpp>

#include <unistd.h>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <memory>
#include <stdexcept>

namespace eical::tools {
namespace {

void use_uri(const std::string& uri) {
  if (!uri.empty()) ::setenv("CYCLONEDDS_URI", uri.c_str(), 1);
}

// DIR/<program id>.trace.csv with the trace's own column names; written whole, then renamed.
void save_trace(const std::filesystem::path& dir, const drivers::dds::TraceMsg& t) {
  std::filesystem::create_directories(dir);
  const auto file = dir / (t.program_id + ".trace.csv");
  const auto tmp = dir / (t.program_id + ".trace.csv.tmp");
  {
    std::ofstream os(tmp, std::ios::trunc);
    if (!os) throw std::runtime_error(tmp.string() + ": cannot write");
    os << t.x_name << ',' << t.y_name << ",series" << (t.cw.empty() ? "" : ",direction") << '\n';
    char line[96];
    for (std::size_t i = 0; i < t.x.size() && i < t.y.size(); ++i) {
      std::snprintf(line, sizeof line, "%.9g,%.9g,%d", t.x[i], t.y[i], i < t.series.size() ? t.series[i] : 0);
      os << line;
      if (!t.cw.empty()) os << (i < t.cw.size() && t.cw[i] ? ",cw" : ",ccw");
      os << '\n';
    }
    if (!os.flush()) throw std::runtime_error(tmp.string() + ": write failed");
  }
  std::filesystem::rename(tmp, file);
}

// ", 2 triggers refused, 1 decode errors": the counters of a Status that are not zero.
std::string nonzero_counters(const drivers::dds::StatusMsg& s) {
  std::string out;
  drivers::dds::for_each_counter(s.counters, [&](const drivers::dds::StatusCounterView& c) {
    if (c.trouble && c.value != 0) out += ", " + std::to_string(c.value) + " " + c.label;
  });
  return out;
}

// What `eical hmi` and `eical trigger` are told. One set for both commands: the two
// register their options on the same fields.
struct HmiOptions {
  int domain = 0, results = 0, traces = 0;
  std::string save_traces;
  double timeout_s = 0.0, connect_timeout_s = 10.0;
  std::string uri;
  int code = 0;
  double p = kNaN, q = kNaN;
};

void add_hmi_options(CLI::App& hmi, HmiOptions& o) {
  hmi.add_option("--domain", o.domain, "DDS domain id")->default_val(0);
  hmi.add_option("--dds-config", o.uri, "Cyclone DDS XML (file://...); default $CYCLONEDDS_URI");
  hmi.add_option("--results", o.results, "exit after this many results (0 = run until the timeout)")->default_val(0);
  hmi.add_option("--traces", o.traces, "also wait for this many traces before exiting with --results")->default_val(0);
  hmi.add_option("--save-traces", o.save_traces, "write every trace received to DIR/<program id>.trace.csv");
  hmi.add_option("--timeout", o.timeout_s, "exit after this many seconds (0 = never)")->default_val(0.0);
  hmi.add_option("--connect-timeout", o.connect_timeout_s,
                 "exit non-zero when no eicald Status arrives within this many seconds")
      ->default_val(10.0);
}

// What the HMI has received so far.
struct HmiTally {
  int results = 0, traces = 0;
  bool daemon_seen = false;
  // The daemon's result count as this HMI knows it: a Result carries the count it was
  // published with, so a Status that left before it can never show fewer.
  std::uint64_t result_count = 0;
};

void print_status(const drivers::dds::StatusMsg& s, HmiTally& tally) {
  tally.daemon_seen = true;
  tally.result_count = std::max(tally.result_count, s.results);
  std::printf("status %s: %s, %llu frames, %llu overruns, %llu lost, %llu results%s%s%s\n", s.daemon.c_str(),
              s.state.c_str(), static_cast<unsigned long long>(s.frames), static_cast<unsigned long long>(s.overruns),
              static_cast<unsigned long long>(s.frames_lost), static_cast<unsigned long long>(tally.result_count),
              nonzero_counters(s).c_str(), s.fault.empty() ? "" : " — ", s.fault.c_str());
}

// The figures with their uncertainty and the verdict, from the result document.
void print_result(const drivers::dds::ResultMsg& r, HmiTally& tally) {
  std::string verdict = r.degraded ? "degraded" : "ok", g = "G n/a";
  const auto doc = nlohmann::json::parse(r.json, nullptr, false);
  if (!doc.is_discarded()) {
    verdict = doc.value("/quality/verdict"_json_pointer, verdict);
    const auto v = drivers::figure_value(doc, "circle.circular_deviation_G_um");
    const auto u = drivers::uncertainty_k2(doc, "circle.circular_deviation_G_um");
    char b[96];
    if (v)
      std::snprintf(b, sizeof b, "G %.2f%s um%s", *v,
                    u ? (" ± " + std::to_string(*u).substr(0, std::to_string(*u).find('.') + 3)).c_str() : "",
                    u && !drivers::figure_resolved(doc, "circle.circular_deviation_G_um") ? " (not resolved)" : "");
    if (v) g = b;
  }
  tally.daemon_seen = true;
  tally.result_count = std::max(tally.result_count, r.results);
  std::printf("result %s (%s): verdict %s, %s, mean radius deviation %.2f um (result %llu of the daemon)\n",
              r.program_id.c_str(), r.program.c_str(), verdict.c_str(), g.c_str(), r.radius_mean_deviation_um,
              static_cast<unsigned long long>(r.results));
  ++tally.results;
}

void print_trace(const drivers::dds::TraceMsg& t, const HmiOptions& o, HmiTally& tally) {
  const auto [lo, hi] = std::minmax_element(t.y.begin(), t.y.end());
  std::printf("trace %s (%s): %zu points, %s -> %s, %s %.3f .. %.3f (every %u. point)\n", t.program_id.c_str(),
              t.program.c_str(), t.x.size(), t.x_name.c_str(), t.y_name.c_str(), t.y_name.c_str(),
              t.y.empty() ? std::nan("") : *lo, t.y.empty() ? std::nan("") : *hi, t.decimation);
  if (!o.save_traces.empty()) save_trace(o.save_traces, t);
  ++tally.traces;
}

std::chrono::steady_clock::time_point after(std::chrono::steady_clock::time_point t0, double s) {
  return t0 + std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(s));
}

// Prints what arrives until the timeout, the results (and traces) asked for, or no daemon
// within the connect timeout; an error when the daemon or the results asked for never came.
void run_hmi(const HmiOptions& o) {
  use_uri(o.uri);
  drivers::dds::Bus bus(o.domain, drivers::dds::Role::hmi);
  const auto t0 = std::chrono::steady_clock::now();
  const auto end = after(t0, o.timeout_s > 0 ? o.timeout_s : 1e9);
  const auto connect_end = after(t0, o.connect_timeout_s);
  HmiTally tally;
  while (std::chrono::steady_clock::now() < end) {
    if (!tally.daemon_seen && std::chrono::steady_clock::now() >= connect_end) break;
    if (auto s = bus.take_status(std::chrono::milliseconds(100))) print_status(*s, tally);
    if (auto r = bus.take_result(std::chrono::milliseconds(10))) print_result(*r, tally);
    if (auto t = bus.take_trace(std::chrono::milliseconds(10))) print_trace(*t, o, tally);
    std::fflush(stdout);
    if (o.results > 0 && tally.results >= o.results && tally.traces >= o.traces) return;
  }
  if (!tally.daemon_seen) {
    const double waited = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    throw std::runtime_error("hmi: no eicald on DDS domain " + std::to_string(o.domain) + " (no Status within " +
                             std::to_string(static_cast<int>(std::lround(waited))) +
                             " s; is eicald running with the same domain and DDS configuration?)");
  }
  if (o.results > 0)
    throw std::runtime_error("hmi: " + std::to_string(tally.results) + " of " + std::to_string(o.results) +
                             " results and " + std::to_string(tally.traces) + " of " + std::to_string(o.traces) +
                             " traces before the timeout");
}

void add_trigger_options(CLI::App& trig, HmiOptions& o) {
  trig.add_option("code", o.code, "101 (tare + start), 102 (segment), 103 (stop + evaluate)")
      ->required()
      ->check(CLI::IsMember({dsp::trigger::program_start, dsp::trigger::segment_mark, dsp::trigger::program_end}));
  trig.add_option("-P", o.p, "the M-code's P word");
  trig.add_option("-Q", o.q, "the M-code's Q word");
  trig.add_option("--domain", o.domain, "DDS domain id")->default_val(0);
  trig.add_option("--dds-config", o.uri, "Cyclone DDS XML (file://...); default $CYCLONEDDS_URI");
  trig.add_option("--timeout", o.timeout_s, "seconds to wait for eicald's reply")->default_val(3.0);
}

// The trigger command as stamped at `ts` (the M-code's moment).
drivers::dds::CommandMsg trigger_command(const HmiOptions& o, const timespec& ts) {
  drivers::dds::CommandMsg c;
  c.sender = "eical-trigger-" + std::to_string(::getpid());
  c.request_id = 1;
  c.action = "trigger";
  c.code = o.code;
  c.p = o.p;
  c.q = o.q;
  c.time_ns = static_cast<std::int64_t>(ts.tv_sec) * 1000000000 + ts.tv_nsec;
  return c;
}

void run_trigger(const HmiOptions& o) {
  use_uri(o.uri);
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);  // the M-code's moment, before any DDS latency
  drivers::dds::Bus bus(o.domain, drivers::dds::Role::hmi);
  const drivers::dds::CommandMsg c = trigger_command(o, ts);
  const auto end = after(std::chrono::steady_clock::now(), o.timeout_s);
  // Volatile command topic: resend until the daemon's reader has matched and replied.
  while (std::chrono::steady_clock::now() < end) {
    bus.send(c);
    if (auto r = bus.take_reply(std::chrono::milliseconds(100));
        r && r->sender == c.sender && r->request_id == c.request_id) {
      std::printf("M%d: %s (state %s)\n", o.code, r->message.c_str(), r->state.c_str());
      if (!r->ok) throw std::runtime_error("trigger refused: " + r->message);
      return;
    }
  }
  throw std::runtime_error("trigger: no eicald answered on DDS domain " + std::to_string(o.domain) + " within " +
                           std::to_string(o.timeout_s) + " s");
}

}  // namespace

void register_hmi(CLI::App& app) {
  auto o = std::make_shared<HmiOptions>();
  auto* hmi = app.add_subcommand("hmi", "Reference HMI: print eicald's status and results from the DDS bus");
  add_hmi_options(*hmi, *o);
  hmi->callback([o] { run_hmi(*o); });
  auto* trig = app.add_subcommand("trigger", "Send an NC trigger (M101/M102/M103) to eicald over DDS");
  add_trigger_options(*trig, *o);
  trig->callback([o] { run_trigger(*o); });
}

}  // namespace eical::tools
#else
namespace eical::tools {
void register_hmi(CLI::App& app) {
  auto* hmi = app.add_subcommand("hmi", "Reference HMI (this build has no DDS)");
  hmi->callback(
      [] { throw std::runtime_error("eical was built without Cyclone DDS (EICAL_BUILD_DAEMON=OFF): no hmi/trigger"); });
}
}  // namespace eical::tools
#endif
