// UTC time as eical writes it (history/record/utc_time): RFC 3339 by default, any strftime
// format when asked (the daemon's run ids).
#include "history/record/utc_time.hpp"

#include <gtest/gtest.h>

#include <regex>

namespace eical::history {
namespace {

TEST(UtcTime, Rfc3339ByDefaultAndAnyFormatWhenAsked) {
  EXPECT_EQ(utc_text(0), "1970-01-01T00:00:00Z");
  EXPECT_EQ(utc_text(1796220528), "2026-12-02T14:08:48Z");
  EXPECT_EQ(utc_text(1796220528, "%Y%m%dT%H%M%SZ"), "20261202T140848Z");
  EXPECT_TRUE(std::regex_match(utc_now(), std::regex(R"(\d{4}-\d\d-\d\dT\d\d:\d\d:\d\dZ)"))) << utc_now();
}

}  // namespace
}  // namespace eical::history
