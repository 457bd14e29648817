// Two analyses of one run whose draws must give the same U (other executors, a screen that
// did not stop): every figure's U, element by element, bit for bit; a U that could not be
// estimated in one could not be in the other either.
#pragma once

#include "dsp/analysis/analyze_run.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstddef>

namespace eical::testing {

inline void expect_same_uncertainty(const dsp::Analysis& a, const dsp::Analysis& b) {
  ASSERT_GE(a.uncertainty_k2.size(), 10u) << a.uncertainty_note;
  ASSERT_EQ(a.uncertainty_k2.size(), b.uncertainty_k2.size());
  for (const auto& [key, u] : a.uncertainty_k2) {
    const auto it = b.uncertainty_k2.find(key);
    ASSERT_NE(it, b.uncertainty_k2.end()) << key;
    ASSERT_EQ(it->second.size(), u.size()) << key;
    for (std::size_t e = 0; e < u.size(); ++e)
      if (std::isfinite(u[e]))
        EXPECT_EQ(it->second[e], u[e]) << key << "[" << e << "]";
      else
        EXPECT_FALSE(std::isfinite(it->second[e])) << key << "[" << e << "]";
  }
}

}  // namespace eical::testing
