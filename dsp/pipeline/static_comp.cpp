#include "dsp/pipeline/static_comp.hpp"

namespace eical::dsp {

StaticComp::StaticComp(const SensorSpec& spec, const Acquisition& acq, const Site& site)
    : to_machine(spec.to_machine),
      volts_per_count_over_k1(acq.adc_lsb_volt / spec.k1_v_per_g.array()),
      bias_g(spec.bias_g),
      k2(spec.k2_g_per_g2),
      k3(spec.k3_g_per_g3),
      offset_counts(static_cast<double>(acq.adc_offset_counts)),
      g_mps2(site.g_mps2) {}

}  // namespace eical::dsp
