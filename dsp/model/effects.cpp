#include "dsp/model/effects.hpp"

#include <stdexcept>

namespace eical::dsp::model {

const std::array<EffectInfo, kEffectCount>& effect_catalogue() {
  using enum Effect;
  using enum EffectSide;
  // clang-format off
  static const std::array<EffectInfo, kEffectCount> table = {{
    {sensor_scale, "sensor.scale", "ppm", 1000.0, 5e4, 1.5e5, sensor, true,
     "a servo accelerometer's scale is known to ±1 %, a MEMS chip's to ±10 %: beyond 5 % (15 %) the wrong sensor, gain or unit is configured"},
    {sensor_bias_drift, "sensor.bias_drift", "ug/s", 0.3, 10.0, 1000.0, sensor, false,
     "10 µg/s is a bias moving by 0.6 mg a minute — a servo sensor warming fast; a drift the standstills do not show is none"},
    {sensor_nonlinearity, "sensor.nonlinearity", "1e-6/g", 200.0, 2e4, 1e5, sensor, true,
     "2 %/g is a hundred times a servo accelerometer's data-sheet k2, k3 (MEMS: 10 %/g)"},
    {sensor_cross_coupling, "sensor.cross_coupling", "ppm", 500.0, 2e4, 5e4, sensor, true,
     "2 % (MEMS 5 %) of one axis' acceleration on another is beyond any data sheet: a mounting error instead"},
    {sensor_misalignment, "sensor.misalignment", "mrad", 1.0, 50.0, 50.0, sensor, true,
     "50 mrad (3°) is no careful mounting but another one: a sign flip, swap or mirror is reported with the mounting that fits"},
    {sensor_dynamics, "sensor.dynamics", "us", 15.0, 500.0, 5000.0, sensor, true,
     "2ζ/ω0 of a sensor with f0 above 300 Hz and ζ below 1 stays under 1 ms; a 500 µs error is a wrong data sheet or a timing problem"},
    {sensor_damping_amplitude, "sensor.damping_amplitude", "1/g", 0.2, 10.0, 10.0, sensor, true,
     "damping doubling per 0.1 g is beyond squeeze-film damping (ch. 8.3.1)"},
    {sensor_scale_temperature, "sensor.scale_temperature", "ppm over the run (1 ug as 50 ppm)", 50.0, 5e4, 5e4, sensor, true,
     "500 ppm/°C and 900 µg/°C are ten times a servo sensor's data sheet (70 ppm/°C, 100 µg/°C)"},
    {daq_group_delay, "daq.group_delay", "samples", 0.3, 100.0, 100.0, daq, true,
     "a decimation filter delays by tens of samples; 100 samples off is a clock or time-stamp problem"},
    {site_coriolis, "site.coriolis", "ug", 1.0, 1e9, 1e9, site, true,
     "the Earth's rate is known: tested at the site's value, never fitted freely"},
    {machine_common_vibration, "machine.common_vibration", "mg", 0.05, 5000.0, 5000.0, machine, false,
     "5 g of floor or frame vibration would stop a machine tool"},
    {machine_differential_vibration, "machine.differential_vibration", "um", 0.1, 1000.0, 1000.0, machine, false,
     "a millimetre of head against table is a crash, not a vibration"},
    {machine_backlash, "machine.backlash", "um", 1.0, 500.0, 500.0, machine, false,
     "half a millimetre of lost motion is a broken drive, not backlash"},
    {machine_reversal_spike, "machine.reversal_spike", "um", 1.0, 200.0, 200.0, machine, false,
     "friction holds a tuned axis back by micrometres, not 0.2 mm"},
    {machine_servo_mismatch, "machine.servo_mismatch", "ms", 0.05, 5.0, 5.0, machine, false,
     "position loops of one machine (Kv 10–100/s, feed-forward) differ in lag by well under 5 ms"},
    {machine_squareness, "machine.squareness", "urad", 10.0, 2000.0, 2000.0, machine, false,
     "2 mrad (0.1°) out of square is a collision-bent machine; 0.37 rad is not a machine"},
    {machine_scale_mismatch, "machine.scale_mismatch", "ppm", 10.0, 2000.0, 2000.0, machine, false,
     "ball-screw pitch and thermal growth reach a few hundred ppm; −78 % is a wrong unit or a missing motion"},
    {machine_cyclic_error, "machine.cyclic_error", "um", 0.5, 100.0, 100.0, machine, false,
     "a screw's periodic error is micrometres; 0.1 mm is a broken nut"},
    {machine_straightness, "machine.straightness", "um", 1.0, 500.0, 500.0, machine, false,
     "guideways bow by micrometres per 100 mm; half a millimetre is a bent machine"},
    {machine_stick_slip, "machine.stick_slip", "bursts per creep zone", 8.0, 1e9, 1e9, machine, false,
     "counted, not fitted: no bound"},
    {machine_resonance, "machine.resonance", "amplification", 0.1, 1000.0, 1000.0, machine, false,
     "modes between 1 Hz and a third of the sensors' natural frequency, damping 0.002–0.4, found from the frequency response"},
  }};
  // clang-format on
  return table;
}

const EffectInfo& info(Effect e) { return effect_catalogue()[static_cast<std::size_t>(e)]; }

std::string_view name(Effect e) { return info(e).name; }

std::optional<Effect> effect_named(std::string_view name) {
  for (const auto& i : effect_catalogue())
    if (i.name == name) return i.id;
  return std::nullopt;
}

}  // namespace eical::dsp::model
