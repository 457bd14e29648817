// The Trace topic over loopback: the arrays behind a result's plot arrive intact, and an
// HMI that joins after the publication still gets the last trace per program id
// (reliable, transient-local).
#include "drivers/dds/bus.hpp"
#include "drivers/dds/domain_claim.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>

namespace eical::drivers::dds {
namespace {

using namespace std::chrono_literals;

int trace_domain() {
  ::setenv("CYCLONEDDS_URI", "file://" EICAL_SOURCE_DIR "/config/cyclonedds-loopback.xml", 1);
  return eical::drivers::dds::claim_free_domain();
}

TraceMsg circle_trace(const std::string& id, std::size_t n) {
  TraceMsg t;
  t.program_id = id;
  t.program = "circle";
  t.x_name = "angle_deg";
  t.y_name = "radius_deviation_um";
  for (std::size_t i = 0; i < n; ++i) {
    t.x.push_back(360.0 * static_cast<double>(i) / static_cast<double>(n));
    t.y.push_back(0.25 * static_cast<double>(i % 17) - 2.0);
    t.series.push_back(static_cast<std::int32_t>(i / 1000));
    t.cw.push_back(i % 3 == 0);
  }
  t.decimation = 4;
  return t;
}

TEST(DdsTrace, LateHmiReceivesTheLastTracePerProgram) {
  const int domain = trace_domain();
  Bus daemon(domain, Role::daemon);
  const TraceMsg a = circle_trace("run-a", 5000), b = circle_trace("run-b", 12);
  ASSERT_TRUE(daemon.publish(a));
  ASSERT_TRUE(daemon.publish(b));
  Bus hmi(domain, Role::hmi);  // joins after both were published
  std::optional<TraceMsg> got_a, got_b;
  const auto end = std::chrono::steady_clock::now() + 10s;
  while ((!got_a || !got_b) && std::chrono::steady_clock::now() < end) {
    if (auto t = hmi.take_trace(200ms)) (t->program_id == "run-a" ? got_a : got_b) = *t;
  }
  ASSERT_TRUE(got_a) << "trace run-a not delivered to a late HMI";
  ASSERT_TRUE(got_b) << "trace run-b not delivered to a late HMI";
  EXPECT_EQ(got_a->program, "circle");
  EXPECT_EQ(got_a->x_name, "angle_deg");
  EXPECT_EQ(got_a->y_name, "radius_deviation_um");
  EXPECT_EQ(got_a->x, a.x);
  EXPECT_EQ(got_a->y, a.y);
  EXPECT_EQ(got_a->series, a.series);
  EXPECT_EQ(got_a->cw, a.cw);
  EXPECT_EQ(got_a->decimation, 4u);
  EXPECT_EQ(got_b->x.size(), 12u);
}

}  // namespace
}  // namespace eical::drivers::dds
