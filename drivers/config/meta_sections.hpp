#pragma once
// The metadata sections shared by run.toml, the daemon config and simulation scenarios
// ([acquisition], [site], [machine], [envelope], [sensors.*], [[psd]]), read strictly: same key names
// and units as docs/run-format.md, so a value can be copied between the files.
#include "drivers/config/strict_toml.hpp"
#include "dsp/core/run_meta.hpp"

namespace eical::drivers {

// Each reader starts from `defaults`, overrides the keys present and checks types and
// ranges. Every file is strict, recorded runs too: an unknown key is an error naming file,
// line and key (a misspelt k1_v_per_g would otherwise leave the sensitivity at its default);
// keys of other tools go in the extension namespace ext_ (docs/run-files.md).
dsp::Acquisition read_acquisition(StrictTable t, const dsp::Acquisition& defaults = {});
dsp::Site read_site(StrictTable t, const dsp::Site& defaults = {});
dsp::MachineLayout read_machine(StrictTable t, const dsp::MachineLayout& defaults = {});
dsp::SensorSpec read_sensor(StrictTable t, const dsp::SensorSpec& defaults = {});
dsp::PsdSpec read_psd(StrictTable t);
dsp::Program read_program(StrictTable t);
dsp::SetPointOrigin read_setpoint_origin(StrictTable t);
// [envelope] (dsp/core/work_envelope.hpp): travel_x_mm/travel_y_mm/travel_z_mm = [min, max],
// max_feed_mm_min, max_accel_mm_s2. Always strict, in run.toml too: a mistyped limit must
// not fall back to the default it was meant to change.
dsp::WorkEnvelope read_envelope(StrictTable t, const dsp::WorkEnvelope& defaults = {});

}  // namespace eical::drivers
