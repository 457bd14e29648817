#pragma once
// The DAQ's anti-alias/decimation filter (ΣΔ ADC class of the NI PCI-4474, appendix A2):
// the sensor signal is sampled internally at oversample·fs and a linear-phase FIR with its
// pass band to 0.4863 fs decimates it to fs. A linear-phase FIR of 2M+1 taps delays by M
// input samples, so the data sheet's 38.8-sample group delay fixes the filter's length
// (M = 388 at 10× oversampling); a delay that differs from the design is an extra
// integer shift plus a linear interpolation on the internal grid (band-limited signal,
// ≪ internal Nyquist: the interpolation error is far below the ADC's resolution).
// Kaiser window (β for ~90 dB stop band), DC gain exactly 1.
#include <cstddef>
#include <vector>

namespace eical::sim {

class DecimationFilter {
 public:
  // delay_samples at the output rate; design_delay_samples sets the FIR length.
  DecimationFilter(int oversample, double delay_samples, double passband_fs = 0.4863,
                   double design_delay_samples = 38.8);

  // in[k] at t = k/(oversample·fs), k < n_in; out[n] = filtered signal at t = n/fs,
  // delayed. Before t = 0 the input is held at in[0] (the sensor rested), after the end
  // at its last value.
  void apply(const std::vector<double>& in, double* out, std::size_t n_out) const;

  // The filtered signal at fractional output positions (output sample units, e.g. a
  // sample taken a little early or late): the output at the neighbouring internal
  // samples, interpolated linearly (the output is band-limited far below the internal
  // Nyquist frequency).
  void apply_at(const std::vector<double>& in, const double* positions, double* out, std::size_t n_out) const;

  [[nodiscard]] std::size_t taps() const { return 2 * taps_half_.size() - 1; }
  // Gain at f (fraction of the output rate), for tests.
  [[nodiscard]] double gain(double f_over_fs) const;

 private:
  // The filter's output centred on internal sample c of x (the ends held).
  [[nodiscard]] double output_at(const std::vector<double>& x, long c) const;

  int ov_;
  long shift_;                     // integer part of the delay, internal samples
  double frac_;                    // fractional part
  std::vector<double> taps_half_;  // h[0..M]; h[−j] = h[j]
};

}  // namespace eical::sim
