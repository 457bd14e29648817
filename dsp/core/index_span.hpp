#pragma once
// Where a stretch of sample indices lies in an ascending index vector: the positions
// [begin, end) of the entries in [first, last). Binary search, so an evaluation that cuts a
// trace into revolutions does not scan the whole trace for each of them.
#include "dsp/core/error.hpp"

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace eical::dsp {

struct IndexSpan {
  std::size_t begin = 0, end = 0;
  [[nodiscard]] std::size_t size() const noexcept { return end - begin; }
};

inline IndexSpan index_span(const std::vector<std::int64_t>& ascending, std::int64_t first, std::int64_t last) {
  const auto lo = std::lower_bound(ascending.begin(), ascending.end(), first);
  const auto hi = std::lower_bound(lo, ascending.end(), std::max(first, last));
  return {static_cast<std::size_t>(lo - ascending.begin()), static_cast<std::size_t>(hi - ascending.begin())};
}

// The evaluations' precondition for index_span: a trace's sample indices ascend (the
// pipeline's do; a trace assembled otherwise is refused by name).
inline void require_ascending(const std::vector<std::int64_t>& sample_index, const char* what) {
  if (!std::is_sorted(sample_index.begin(), sample_index.end()))
    throw InputError(std::string(what) + ": sample indices do not ascend");
}

}  // namespace eical::dsp
