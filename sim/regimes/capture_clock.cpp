#include "sim/regimes/capture_clock.hpp"

#include "dsp/core/error.hpp"
#include "sim/simulate.hpp"

#include <algorithm>
#include <cmath>
#include <random>

namespace eical::sim {

CaptureSamples capture_samples(const CaptureClock& clock, std::size_t n_frames, double fs_hz) {
  if (!(fs_hz > 0.0) || n_frames < 2)
    throw dsp::InputError("capture clock: need at least two samples and a positive rate");
  if (clock.batch < 1 || clock.lost_batches < 0)
    throw dsp::InputError("capture clock: batch must be >= 1 and lost_batches >= 0");
  if (!(clock.jitter_rms_s >= 0.0) || !std::isfinite(clock.offset_s))
    throw dsp::InputError("capture clock: jitter must not be negative, the offset finite");
  const std::size_t batch = static_cast<std::size_t>(clock.batch), n_batches = (n_frames + batch - 1) / batch;
  std::mt19937_64 rng(stream_seed(clock.seed, 9001));
  std::vector<bool> lost_batch(n_batches, false);
  if (n_batches > 2) {
    std::vector<std::size_t> inner(n_batches - 2);
    for (std::size_t b = 0; b < inner.size(); ++b) inner[b] = b + 1;
    std::shuffle(inner.begin(), inner.end(), rng);
    for (std::size_t k = 0; k < std::min<std::size_t>(inner.size(), static_cast<std::size_t>(clock.lost_batches)); ++k)
      lost_batch[inner[k]] = true;
  }
  std::normal_distribution<double> unit(0.0, 1.0);
  const double clip = 0.4 / fs_hz;
  CaptureSamples out;
  out.jitter_s.resize(n_frames);
  out.kept.resize(n_frames);
  double sum2 = 0.0;
  std::size_t kept = 0;
  for (std::size_t k = 0; k < n_frames; ++k) {
    const double j = std::clamp(clock.jitter_rms_s * unit(rng), -clip,
                                clip);  // drawn for every frame: a lost batch shifts no other draw
    // The first and last sample stay on the grid: the capture spans the run exactly.
    out.jitter_s[k] = (k == 0 || k + 1 == n_frames) ? 0.0 : j;
    out.kept[k] = !lost_batch[k / batch];
    if (!out.kept[k]) {
      ++out.lost;
      continue;
    }
    sum2 += out.jitter_s[k] * out.jitter_s[k];
    ++kept;
  }
  out.jitter_rms_s = std::sqrt(sum2 / static_cast<double>(kept));
  return out;
}

}  // namespace eical::sim
