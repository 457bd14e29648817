#pragma once
// How another system samples and stamps what it records (a Klipper capture, a logger's
// CSV): frame n of the run is truly taken at n/fs + jitter_n (a host reading the chip in
// batches over SPI or I2C takes each a little early or late) and stamped with that time
// on the capture's clock, t_c = offset_s + t; whole batches get lost. A recording made
// this way holds the signal at its stamps, so resampling it onto a uniform clock by
// interpolation recovers the signal (what `eical import` does).
// The capture clock runs at the rate of the clock the set-point is on (Klipper stamps its
// captures in print time, the moves' own clock); the importers estimate an offset only.
#include <cstdint>
#include <vector>

namespace eical::sim {

struct CaptureClock {
  double offset_s = 0.0;      // capture-clock time of the run's t = 0
  double jitter_rms_s = 0.0;  // per sample, Gaussian, clipped to ±0.4/fs (stamps increase)
  int batch = 16;             // samples read at once
  int lost_batches = 0;       // batches dropped, never the first or the last
  std::uint64_t seed = 1;
};

struct CaptureSamples {
  std::vector<double> jitter_s;  // per frame: true sampling time − n/fs (0 at the ends)
  std::vector<bool> kept;        // false: lost with its batch
  std::size_t lost = 0;
  double jitter_rms_s = 0.0;  // rms of the jitter of the kept samples
  [[nodiscard]] double stamp_s(std::size_t n, double fs_hz, const CaptureClock& clock) const {
    return clock.offset_s + static_cast<double>(n) / fs_hz + jitter_s[n];
  }
};

// The sampling of a capture of n frames at fs_hz.
CaptureSamples capture_samples(const CaptureClock& clock, std::size_t n_frames, double fs_hz);

}  // namespace eical::sim
