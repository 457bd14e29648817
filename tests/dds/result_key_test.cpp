// Result is keyed by machine and run id: two eicalds on one domain whose runs share an id
// both reach a late collector, with the provenance the calibration history stores.
#include "drivers/dds/bus.hpp"
#include "drivers/dds/domain_claim.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cstdlib>
#include <map>

namespace eical::drivers::dds {
namespace {

using namespace std::chrono_literals;

TEST(DdsResultKey, SameRunIdOnTwoMachinesReachesALateCollectorTwice) {
  ::setenv("CYCLONEDDS_URI", "file://" EICAL_SOURCE_DIR "/config/cyclonedds-loopback.xml", 1);
  const int domain = claim_free_domain();
  Bus a(domain, Role::daemon), b(domain, Role::daemon);
  ResultMsg r;
  r.program_id = "eicald-20261112T091100Z-0";
  r.program = "circle";
  r.json = R"({"format":"eical-result/1"})";
  r.measured_at = "2026-11-12T09:11:00Z";
  r.software_version = "eical 0.1.0";
  r.sensor_calibration = "datasheet";
  r.machine = "maho-1", r.run_path = "/var/lib/eical/runs/a";
  ASSERT_TRUE(a.publish(r));
  r.machine = "hermle-2", r.run_path = "/var/lib/eical/runs/b";
  ASSERT_TRUE(b.publish(r));
  Bus collector(domain, Role::hmi);  // joins after both writes: transient-local, one instance per key
  std::map<std::string, ResultMsg> got;
  for (auto end = std::chrono::steady_clock::now() + 10s; got.size() < 2 && std::chrono::steady_clock::now() < end;)
    if (auto m = collector.take_result(200ms)) got[m->machine] = *m;
  ASSERT_EQ(got.size(), 2u);
  EXPECT_EQ(got["maho-1"].run_path, "/var/lib/eical/runs/a");
  EXPECT_EQ(got["hermle-2"].run_path, "/var/lib/eical/runs/b");
  EXPECT_EQ(got["hermle-2"].program_id, r.program_id);
  EXPECT_EQ(got["hermle-2"].measured_at, "2026-11-12T09:11:00Z");
  EXPECT_EQ(got["hermle-2"].software_version, "eical 0.1.0");
  EXPECT_EQ(got["hermle-2"].sensor_calibration, "datasheet");
}

}  // namespace
}  // namespace eical::drivers::dds
