// Every trigger input reaches the measurement: GPIO line events (through the event seam:
// no gpiochip here) and CAN frames (through a socketpair: no PF_CAN here) on the event and
// frame level, the DSP thread's gate, and end to end through eicald's service: an M101
// edge and an M103 frame make one recording whose marks sit where their timestamps say;
// an M101 frame during it is refused and the recording is untouched.
#include "daemon/service/service.hpp"
#include "daemon/triggers/trigger_gate.hpp"
#include "daemon/triggers/trigger_input.hpp"
#include "drivers/can/can_trigger.hpp"
#include "drivers/gpio/gpio_trigger.hpp"
#include "drivers/run_io/run_reader.hpp"
#include "drivers/source/stamped_source.hpp"

#include <gtest/gtest.h>
#include <sys/socket.h>
#include <unistd.h>

#include <deque>
#include <filesystem>
#include <mutex>
#include <random>
#include <thread>

namespace eical::daemon {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

// GPIO line events handed in by the test, as the kernel would deliver them.
class ScriptedGpio final : public drivers::GpioEventSource {
 public:
  void push(drivers::GpioLineEvent e) {
    std::lock_guard lk(mu_);
    events_.push_back(e);
  }
  std::optional<drivers::GpioLineEvent> wait(int timeout_ms) override {
    const auto end = std::chrono::steady_clock::now() + std::chrono::milliseconds(timeout_ms);
    do {
      {
        std::lock_guard lk(mu_);
        if (!events_.empty()) {
          const auto e = events_.front();
          events_.pop_front();
          return e;
        }
      }
      std::this_thread::sleep_for(2ms);  // test double only
    } while (std::chrono::steady_clock::now() < end);
    return std::nullopt;
  }

 private:
  std::mutex mu_;
  std::deque<drivers::GpioLineEvent> events_;
};

TEST(GpioTrigger, LinesBecomeMCodesRisingEdgesOnlyAndBounceIsIgnored) {
  auto events = std::make_unique<ScriptedGpio>();
  ScriptedGpio& gpio = *events;
  drivers::GpioTriggerInput in(std::move(events), {17, 27, 22}, 5'000'000);
  gpio.push({27, true, 1'000'000'000});
  gpio.push({27, true, 1'002'000'000});   // 2 ms later: bounce
  gpio.push({17, false, 1'003'000'000});  // falling edge
  gpio.push({5, true, 1'004'000'000});    // a line that is not ours
  gpio.push({22, true, 1'010'000'000});
  std::vector<drivers::GpioEdge> edges;
  for (int i = 0; i < 5; ++i)
    if (auto e = in.next(50)) edges.push_back(*e);
  ASSERT_EQ(edges.size(), 2u);
  EXPECT_EQ(edges[0].code, 102);
  EXPECT_EQ(edges[0].time_ns, 1'000'000'000) << "the kernel's timestamp, not the read time";
  EXPECT_EQ(edges[1].code, 103);
  EXPECT_EQ(in.bounces(), 1u);
}

TEST(CanTrigger, FramesThroughASocketCarryPWordAndKernelTimeAndRetransmissionsAreIgnored) {
  int sv[2];
  ASSERT_EQ(::socketpair(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0, sv), 0);
  auto in = drivers::CanTriggerInput::from_socket(sv[0], 0x1E0);
  auto send = [&](const can_frame& f) { ASSERT_EQ(::write(sv[1], &f, sizeof f), static_cast<ssize_t>(sizeof f)); };
  const std::int64_t t_send = drivers::monotonic_ns();
  send(drivers::make_can_trigger(0x1E0, 101, 1, 7.0));
  send(drivers::make_can_trigger(0x1E0, 101, 1, 7.0));  // retransmission (same sequence)
  send(drivers::make_can_trigger(0x2E0, 102, 2));       // another id
  send(drivers::make_can_trigger(0x1E0, 103, 3));
  std::this_thread::sleep_for(20ms);  // the kernel stamped them on arrival, not at our read
  std::vector<drivers::CanTriggerEvent> got;
  for (int i = 0; i < 4; ++i)
    if (auto e = in.next(50)) got.push_back(*e);
  ::close(sv[1]);
  ASSERT_EQ(got.size(), 2u);
  EXPECT_EQ(got[0].trigger.code, 101);
  EXPECT_DOUBLE_EQ(got[0].trigger.p, 7.0);
  EXPECT_EQ(got[1].trigger.code, 103);
  EXPECT_TRUE(std::isnan(got[1].trigger.p));
  EXPECT_EQ(in.frames_ignored(), 2u);
  EXPECT_GE(got[0].time_ns, t_send - 1'000'000);
  EXPECT_LT(got[0].time_ns - t_send, 10'000'000) << "received at once, read 20 ms later: the kernel timestamp is used";
}

TEST(TriggerGate, M101DuringAMeasurementAndMarksWithoutOneAreRefused) {
  TriggerGate g;
  auto req = [](int code) {
    TriggerRequest r;
    r.code = code;
    return r;
  };
  EXPECT_EQ(g.decide(req(103), 10, dsp::State::idle).refusal, Refusal::no_measurement);
  EXPECT_TRUE(g.decide(req(101), 100, dsp::State::idle).accepted);
  // Sent ahead: the queued M101 counts before the session has applied it.
  EXPECT_EQ(g.decide(req(101), 120, dsp::State::idle).refusal, Refusal::measurement_running);
  EXPECT_TRUE(g.decide(req(102), 150, dsp::State::idle).accepted);
  EXPECT_TRUE(g.decide(req(103), 200, dsp::State::idle).accepted);
  // After the queued M103 a new program may start.
  EXPECT_TRUE(g.decide(req(101), 300, dsp::State::idle).accepted);
  g.on_frame(400);
  EXPECT_EQ(g.pending(), 0u);
  EXPECT_EQ(g.decide(req(101), 410, dsp::State::measuring).refusal, Refusal::measurement_running);
  EXPECT_EQ(g.decide(req(101), 410, dsp::State::evaluating).refusal, Refusal::busy);
  EXPECT_EQ(g.decide(req(102), 410, dsp::State::fault).refusal, Refusal::fault);
  TriggerVerdict v;
  v.refusal = Refusal::measurement_running;
  v.state = dsp::State::measuring;
  EXPECT_NE(describe(v, 101).find("continues untouched"), std::string::npos) << describe(v, 101);
}

TEST(TriggerInputs, GpioAndCanEdgesStartAndStopAMeasurementOfTheService) {
  const fs::path dir = fs::temp_directory_path() / ("eicald-triggers-" + std::to_string(std::random_device{}()));
  DaemonConfig c;
  c.source.pacing = "realtime";
  c.source.sim_repeats = 1;
  c.source.sim_repeat_program = true;
  c.source.sim_idle_s = 30.0;  // at rest after the program: the triggers below decide
  c.triggers.inputs = {"gpio", "can"};
  c.recording.dir = dir;
  c.recording.gzip = false;
  c.realtime.sched_fifo_priority = 0;
  c.realtime.mlockall = false;
  c.limits.max_measurement_s = 20.0;
  c.dds.config_uri = "file://" EICAL_SOURCE_DIR "/config/cyclonedds-loopback.xml";
  int sv[2];
  ASSERT_EQ(::socketpair(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0, sv), 0);
  ScriptedGpio* gpio = nullptr;
  Service service(c);
  service.set_trigger_inputs([&](const TriggerConfig& t) {
    std::vector<std::unique_ptr<TriggerInput>> v;
    auto events = std::make_unique<ScriptedGpio>();
    gpio = events.get();
    v.push_back(make_gpio_input(std::move(events), t, "gpio test"));
    v.push_back(make_can_input_on_socket(sv[0], t, "can test"));
    return v;
  });
  std::atomic<bool> stop{false};
  std::mutex mu;
  ServiceStatus last;
  std::thread th([&] {
    service.run(stop, [&](const ServiceStatus& s) {
      std::lock_guard lk(mu);
      last = s;
    });
  });
  auto status = [&] {
    std::lock_guard lk(mu);
    return last;
  };
  const auto start_by = std::chrono::steady_clock::now() + 30s;
  while (status().frames < 20000 && std::chrono::steady_clock::now() < start_by) std::this_thread::sleep_for(50ms);
  ASSERT_GE(status().frames, 20000u) << "the simulated DAQ did not run";
  ASSERT_NE(gpio, nullptr);
  // M101 on its GPIO line (kernel time now), 1.2 s later M103 as a CAN frame; an M101
  // CAN frame in between is refused.
  const std::int64_t t101 = drivers::monotonic_ns();
  gpio->push({17, true, t101});
  std::this_thread::sleep_for(600ms);
  const can_frame again = drivers::make_can_trigger(0x1E0, 101, 1, 3.0);
  ASSERT_EQ(::write(sv[1], &again, sizeof again), static_cast<ssize_t>(sizeof again));
  std::this_thread::sleep_for(600ms);
  const std::int64_t t103 = drivers::monotonic_ns();
  const can_frame end = drivers::make_can_trigger(0x1E0, 103, 2);
  ASSERT_EQ(::write(sv[1], &end, sizeof end), static_cast<ssize_t>(sizeof end));
  const auto done_by = std::chrono::steady_clock::now() + 60s;
  while (status().results_written < 1 && std::chrono::steady_clock::now() < done_by) std::this_thread::sleep_for(50ms);
  stop = true;
  th.join();
  ::close(sv[1]);

  const ServiceStatus s = status();
  ASSERT_EQ(s.results_written, 1u) << "one recording expected, fault: " << s.fault;
  EXPECT_EQ(s.counters.triggers_accepted, 2u);
  EXPECT_GE(s.counters.triggers_refused, 1u) << "the M101 during the measurement";
  const auto run = drivers::read_run(fs::path(s.last_result).parent_path());
  std::int64_t i101 = -1, i103 = -1;
  int starts = 0;
  for (const auto& f : run.frames) {
    if (f.trigger == 101) i101 = f.sample_index, ++starts;
    if (f.trigger == 103) i103 = f.sample_index;
  }
  EXPECT_EQ(starts, 1) << "the refused M101 left no mark";
  ASSERT_GE(i101, 0);
  ASSERT_GE(i103, 0);
  // The marks are where their timestamps put them on the DAQ clock (10 kHz): the spacing of
  // the two timestamps within 5 ms (the simulated DAQ's block pacing and the clock fit).
  const double expected = static_cast<double>(t103 - t101) * 1e-9 * run.fs_hz();
  EXPECT_NEAR(static_cast<double>(i103 - i101), expected, 50.0);
  fs::remove_all(dir);
}

TEST(TriggerInputs, AnAbsentDeviceStopsTheStartNamingIt) {
  DaemonConfig c;
  c.source.pacing = "free_running";
  c.triggers.inputs = {"frame", "gpio"};
  c.triggers.gpio_chip = "gpiochip-nonexistent";
  c.realtime.sched_fifo_priority = 0;
  c.realtime.mlockall = false;
  c.recording.dir = fs::temp_directory_path() / "eicald-absent-gpio";
  c.dds.config_uri = "file://" EICAL_SOURCE_DIR "/config/cyclonedds-loopback.xml";
  std::atomic<bool> stop{false};
  try {
    Service(c).run(stop, [](const ServiceStatus&) {});
    FAIL() << "started without its GPIO chip";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("gpio: cannot open gpiochip-nonexistent"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace eical::daemon
