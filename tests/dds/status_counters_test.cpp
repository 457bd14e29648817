// The status counters' list (drivers/dds/status_counters.hpp) and eical.idl's Status agree
// both ways: copy_counters fails to compile when the IDL lacks a listed counter, and this
// test fails when the IDL carries a counter the list does not.
#include "drivers/dds/status_counters.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

namespace eical::drivers::dds {
namespace {

// The `unsigned long long` fields of eical.idl's Status after its "Every counter" comment.
std::vector<std::string> idl_status_counters() {
  std::ifstream in(std::string(EICAL_SOURCE_DIR) + "/drivers/dds/eical.idl");
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string idl = ss.str();
  const auto status = idl.find("struct Status {");
  const auto counters = idl.find("Every counter", status);
  const auto end = idl.find("};", status);
  if (status == std::string::npos || counters == std::string::npos || counters > end) return {};
  const std::string body = idl.substr(counters, end - counters);
  std::vector<std::string> names;
  const std::regex field(R"(unsigned long long\s+(\w+)\s*;)");
  for (std::sregex_iterator it(body.begin(), body.end(), field), e; it != e; ++it) names.push_back((*it)[1]);
  return names;
}

TEST(DdsStatusCounters, MatchTheIdl) {
  std::vector<std::string> listed;
  for_each_counter(StatusCounters{}, [&](const StatusCounterView& c) { listed.emplace_back(c.name); });
  const std::vector<std::string> idl = idl_status_counters();
  ASSERT_FALSE(idl.empty()) << "eical.idl: no Status counters found after \"Every counter\"";
  EXPECT_EQ(listed, idl);
}

TEST(DdsStatusCounters, VisitEachOnceWithItsValue) {
  StatusCounters c;
  std::uint64_t v = 0;
  for (auto f : kStatusCounterFields) c.*f = ++v;
  std::uint64_t seen = 0, sum = 0, trouble = 0;
  for_each_counter(c, [&](const StatusCounterView& x) {
    ++seen, sum += x.value, trouble += x.trouble ? 1 : 0;
    EXPECT_EQ(x.value, seen) << x.name;  // in the list's order
  });
  EXPECT_EQ(seen, std::size(kStatusCounterFields));
  EXPECT_EQ(sum, seen * (seen + 1) / 2);
  EXPECT_GT(trouble, 0u);
  EXPECT_LT(trouble, seen);
}

}  // namespace
}  // namespace eical::drivers::dds
