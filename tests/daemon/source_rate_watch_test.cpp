// SourceRateWatch: the delivered rate from acquisition stamps against fs_hz, over a sliding
// 4 s window (judged once it is full); off beyond 5 %, too slow only where it matters (DAQs).
#include "daemon/service/source_rate_watch.hpp"

#include <gtest/gtest.h>

namespace {

using eical::daemon::SourceRateWatch;

// Feeds `seconds` of stamps every 50 ms (a status tick) at `rate` samples/s; the last verdict.
double feed(SourceRateWatch& w, double rate, double seconds, std::int64_t& index, std::int64_t& t_ns) {
  double verdict = 0.0;
  for (double t = 0; t < seconds; t += 0.05) {
    t_ns += 50'000'000;
    index += static_cast<std::int64_t>(rate * 0.05);
    verdict = w.observe(index, t_ns);
  }
  return verdict;
}

TEST(SourceRateWatch, OffRatesAreSaidAndClearAfterAWindow) {
  SourceRateWatch w(10000.0, true);
  std::int64_t index = 0, t = 1'000'000'000;
  EXPECT_EQ(feed(w, 10000.0, 6.0, index, t), 0.0);
  EXPECT_NEAR(feed(w, 30000.0, 2.0, index, t), 2.0, 0.03) << "the window holds 2 s of each rate";
  EXPECT_NEAR(feed(w, 30000.0, 4.0, index, t), 3.0, 0.01);
  EXPECT_EQ(feed(w, 10000.0, 4.5, index, t), 0.0);
  EXPECT_NEAR(feed(w, 5000.0, 5.0, index, t), 0.5, 0.01);
  EXPECT_EQ(feed(w, 10300.0, 5.0, index, t), 0.0) << "3 % is within the tolerance";
}

TEST(SourceRateWatch, TooSlowOnlyWhereItMattersAndANewNumberingStartsAgain) {
  SourceRateWatch sim(10000.0, false);
  std::int64_t index = 0, t = 1'000'000'000;
  EXPECT_EQ(feed(sim, 5000.0, 6.0, index, t), 0.0);
  EXPECT_NEAR(feed(sim, 20000.0, 6.0, index, t), 2.0, 0.01);
  index = 0;  // the source restarted its sample numbering
  EXPECT_EQ(feed(sim, 10000.0, 1.0, index, t), 0.0);
}

}  // namespace
