// The DDS bus over loopback (config/cyclonedds-loopback.xml), two participants in one
// process: every topic round-trips, Result reaches a late-joining HMI, wake() ends a wait.
#include "drivers/dds/bus.hpp"
#include "drivers/dds/domain_claim.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <thread>

namespace eical::drivers::dds {
namespace {

using namespace std::chrono_literals;

// A domain of its own per test process, so parallel ctest jobs do not see each other.
int domain() {
  static const int d = [] {
    ::setenv("CYCLONEDDS_URI", "file://" EICAL_SOURCE_DIR "/config/cyclonedds-loopback.xml", 1);
    return eical::drivers::dds::claim_free_domain();
  }();
  return d;
}

template <class Take>
auto wait_for(Take&& take, std::chrono::milliseconds total = 5000ms) {
  const auto end = std::chrono::steady_clock::now() + total;
  decltype(take()) got;
  while (!got && std::chrono::steady_clock::now() < end) got = take();
  return got;
}

TEST(DdsBus, StatusAndLiveRoundTrip) {
  Bus daemon(domain(), Role::daemon), hmi(domain(), Role::hmi);
  StatusMsg s;
  s.daemon = "eicald@test";
  s.state = "MEASURING";
  s.fault = "";
  s.frames = 123456789012ull;
  s.overruns = 3;
  s.frames_lost = 2;
  s.temp_table_c = 21.5f;
  s.time_ns = 42;
  // Every counter travels (each a different value: a swapped field shows).
  std::uint64_t value = 1000;
  for (auto c : kStatusCounterFields) s.counters.*c = ++value;
  // Reliable + volatile: publish until the reader has matched and taken one.
  const auto got = wait_for([&] {
    daemon.publish(s);
    return hmi.take_status(100ms);
  });
  ASSERT_TRUE(got);
  EXPECT_EQ(got->daemon, s.daemon);
  EXPECT_EQ(got->state, "MEASURING");
  EXPECT_EQ(got->frames, s.frames);
  EXPECT_EQ(got->overruns, 3u);
  EXPECT_EQ(got->frames_lost, 2u);
  EXPECT_FLOAT_EQ(got->temp_table_c, 21.5f);
  EXPECT_EQ(got->time_ns, 42);
  for (auto c : kStatusCounterFields) EXPECT_EQ(got->counters.*c, s.counters.*c);

  LiveMsg l;
  l.daemon = "eicald@test";
  l.sample_index = 99;
  l.pos_mm = {1.5, -2.25, 3.0};
  l.integrating = true;
  const auto live = wait_for([&] {
    daemon.publish(l);
    return hmi.take_live(100ms);
  });
  ASSERT_TRUE(live);
  EXPECT_EQ(live->pos_mm, l.pos_mm);
  EXPECT_TRUE(live->integrating);
}

TEST(DdsBus, ResultReachesAnHmiThatJoinsLater) {
  Bus daemon(domain(), Role::daemon);
  ResultMsg r;
  r.program_id = "run-0001";
  r.program = "circle";
  r.circular_deviation_G_um = 6.25;
  r.results = 17;
  r.json = R"({"format":"eical-result/1"})";
  ASSERT_TRUE(daemon.publish(r));
  Bus hmi(domain(), Role::hmi);  // created after the write: transient-local delivers it
  const auto got = hmi.take_result(5000ms);
  ASSERT_TRUE(got);
  EXPECT_EQ(got->program_id, "run-0001");
  EXPECT_DOUBLE_EQ(got->circular_deviation_G_um, 6.25);
  EXPECT_TRUE(std::isnan(got->radius_mean_deviation_um));
  EXPECT_EQ(got->results, 17u);
  EXPECT_EQ(got->json, r.json);
}

TEST(DdsBus, CommandAndReply) {
  Bus daemon(domain(), Role::daemon), hmi(domain(), Role::hmi);
  CommandMsg c;
  c.sender = "eical-trigger-1";
  c.request_id = 7;
  c.action = "trigger";
  c.code = 101;
  c.p = 2.0;
  const auto cmd = wait_for([&] {
    hmi.send(c);
    return daemon.take_command(100ms);
  });
  ASSERT_TRUE(cmd);
  EXPECT_EQ(cmd->action, "trigger");
  EXPECT_EQ(cmd->code, 101);
  EXPECT_DOUBLE_EQ(cmd->p, 2.0);
  EXPECT_TRUE(std::isnan(cmd->q));
  ReplyMsg rep{cmd->sender, cmd->request_id, true, "accepted", "MEASURING"};
  const auto reply = wait_for([&] {
    daemon.publish(rep);
    return hmi.take_reply(100ms);
  });
  ASSERT_TRUE(reply);
  EXPECT_EQ(reply->request_id, 7u);
  EXPECT_TRUE(reply->ok);
  EXPECT_EQ(reply->state, "MEASURING");
}

TEST(DdsBus, WakeEndsAWaitingTakePromptly) {
  Bus hmi(domain(), Role::hmi);
  const auto t0 = std::chrono::steady_clock::now();
  std::thread waker([&] {
    std::this_thread::sleep_for(50ms);
    hmi.wake();
  });
  const auto got = hmi.take_status(10000ms);
  waker.join();
  EXPECT_FALSE(got);
  EXPECT_LT(std::chrono::steady_clock::now() - t0, 5000ms);
}

TEST(DdsBus, MalformedConfigIsAClearErrorNotACrash) {
  const int d = domain() + 1;  // initialises the loopback URI first, so it can be replaced below
  const std::string bad = "/tmp/eical-bad-dds-" + std::to_string(::getpid()) + ".xml";
  FILE* f = std::fopen(bad.c_str(), "w");
  ASSERT_NE(f, nullptr);
  std::fputs("<CycloneDDS><Domain><General><NoSuchElement/></General></Domain></CycloneDDS>", f);
  std::fclose(f);
  const char* old = std::getenv("CYCLONEDDS_URI");
  const std::string saved = old ? old : "";
  ::setenv("CYCLONEDDS_URI", ("file://" + bad).c_str(), 1);
  try {
    Bus b(d, Role::hmi);
    ADD_FAILURE() << "a malformed configuration was accepted";
  } catch (const BusError& e) {
    EXPECT_NE(std::string(e.what()).find("CYCLONEDDS_URI"), std::string::npos) << e.what();
  }
  ::setenv("CYCLONEDDS_URI", saved.c_str(), 1);
  std::remove(bad.c_str());
}

}  // namespace
}  // namespace eical::drivers::dds
