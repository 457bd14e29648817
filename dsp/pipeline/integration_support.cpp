#include "dsp/pipeline/integration_support.hpp"

#include <algorithm>
#include <cstdio>

namespace eical::dsp {

std::string unsupported_integration(const Measurement& m) {
  const bool rest_before = static_cast<double>(m.rest_window_samples) >= kMinRestS * m.fs_hz;
  const bool held = rest_before || m.zupt_window_samples > 0 || m.supports.psd_fixes > 0;
  if (held || m.sample_index.empty()) return {};
  const double seconds = static_cast<double>(m.sample_index.back() - m.sample_index.front()) / m.fs_hz;
  const double sigma_um = m.sigma_peak_um;  // over the whole trace (the arrays may keep every n-th sample)
  char buf[240];
  std::snprintf(buf, sizeof buf,
                "no standstill before or after the motion and no position support: the acceleration integrated twice "
                "over %.1f s is no position "
                "(its noise alone: sigma %.3g mm); compare in acceleration (eical explain)",
                seconds, sigma_um * 1e-3);
  return buf;
}

}  // namespace eical::dsp
