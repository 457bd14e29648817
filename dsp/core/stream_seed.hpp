#pragma once
// An independent random stream per purpose, derived from one seed: the simulator's noise
// sources and the uncertainty's Monte Carlo draws each take their generator's seed from it,
// so that a stream depends on (seed, purpose) alone and not on the order it is asked for.
#include <cstdint>

namespace eical::dsp {

// splitmix64 of (seed, purpose): well-separated streams for neighbouring seeds.
constexpr std::uint64_t stream_seed(std::uint64_t seed, std::uint64_t purpose) noexcept {
  std::uint64_t z = seed * 0x9E3779B97F4A7C15ull + purpose * 0xBF58476D1CE4E5B9ull + 0x94D049BB133111EBull;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

}  // namespace eical::dsp
