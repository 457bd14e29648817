// eicald's service on the DDS bus: an HMI in the same process receives the Result of a
// simulated measurement and gets a Reply to a trigger command.
#include "daemon/service/service.hpp"
#include "drivers/dds/bus.hpp"
#include "drivers/dds/domain_claim.hpp"

#include <gtest/gtest.h>
#include <unistd.h>
#include <nlohmann/json.hpp>

#include <atomic>
#include <chrono>
#include <filesystem>
#include <random>
#include <thread>

namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

TEST(ServiceDds, HmiReceivesResultAndCommandsAreAnswered) {
  const int domain = eical::drivers::dds::claim_free_domain();
  const fs::path dir = fs::temp_directory_path() / ("eicald-dds-" + std::to_string(std::random_device{}()));
  eical::daemon::DaemonConfig c;
  c.source.pacing = "free_running";
  c.source.sim_repeats = 1;
  c.source.sim_repeat_program = true;  // keeps running until stopped
  c.source.sim_idle_s = 0.5;
  c.recording.dir = dir;
  c.recording.gzip = false;
  c.realtime.sched_fifo_priority = 0;
  c.realtime.mlockall = false;
  c.limits.max_measurement_s = 20.0;
  c.dds.domain_id = domain;
  c.dds.config_uri = "file://" EICAL_SOURCE_DIR "/config/cyclonedds-loopback.xml";
  std::atomic<bool> stop{false};
  std::thread service([&] { eical::daemon::Service(c).run(stop, [](const eical::daemon::ServiceStatus&) {}); });

  eical::drivers::dds::Bus hmi(domain, eical::drivers::dds::Role::hmi);
  std::optional<eical::drivers::dds::ResultMsg> result;
  // Deadlines, not durations: under ASan with another test on the second core the first
  // Result took close to 30 s; the loops end as soon as it is there.
  const auto deadline = std::chrono::steady_clock::now() + 180s;
  while (!result && std::chrono::steady_clock::now() < deadline) result = hmi.take_result(100ms);
  eical::drivers::dds::CommandMsg cmd;
  cmd.sender = "test";
  cmd.request_id = 5;
  cmd.action = "dance";
  std::optional<eical::drivers::dds::ReplyMsg> reply;
  const auto reply_deadline = std::chrono::steady_clock::now() + 30s;
  while (!reply && std::chrono::steady_clock::now() < reply_deadline) {
    hmi.send(cmd);
    reply = hmi.take_reply(100ms);
  }
  stop = true;
  service.join();
  fs::remove_all(dir);

  ASSERT_TRUE(result) << "no Result on the bus";
  EXPECT_EQ(result->program, "circle");
  const auto j = nlohmann::json::parse(result->json);
  EXPECT_EQ(j["format"], "eical-result/1");
  EXPECT_NEAR(j["circle"]["circular_deviation_G_um"].get<double>(), result->circular_deviation_G_um, 1e-9);
  ASSERT_TRUE(reply) << "no Reply to a command";
  EXPECT_EQ(reply->request_id, 5u);
  EXPECT_FALSE(reply->ok);  // an unknown action is refused, with the reason
  EXPECT_NE(reply->message.find("dance"), std::string::npos);
}

}  // namespace
