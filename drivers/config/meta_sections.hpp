#pragma once
// The metadata sections shared by run.toml, the daemon config and simulation scenarios
// ([acquisition], [site], [machine], [envelope], [sensors.*], [[psd]]), read strictly: same key names
// and units as shared/spec/run-format.md, so a value can be copied between the files.
#include "drivers/config/strict_toml.hpp"
#include "dsp/core/run_meta.hpp"

namespace eical::drivers {

// Each reader starts from `defaults`, overrides the keys present and checks types and
// ranges. Configs are strict (unknown keys are errors); recorded runs may carry keys
// added by others (spec), so run.toml is read with Unknown::accept.
enum class Unknown { reject, accept };
dsp::Acquisition read_acquisition(StrictTable t, const dsp::Acquisition& defaults = {}, Unknown u = Unknown::reject);
dsp::Site read_site(StrictTable t, const dsp::Site& defaults = {}, Unknown u = Unknown::reject);
dsp::MachineLayout read_machine(StrictTable t, const dsp::MachineLayout& defaults = {}, Unknown u = Unknown::reject);
dsp::SensorSpec read_sensor(StrictTable t, const dsp::SensorSpec& defaults = {}, Unknown u = Unknown::reject);
dsp::PsdSpec read_psd(StrictTable t, Unknown u = Unknown::reject);
dsp::Program read_program(StrictTable t, Unknown u = Unknown::reject);
dsp::SetPointOrigin read_setpoint_origin(StrictTable t, Unknown u = Unknown::reject);
// [envelope] (dsp/core/work_envelope.hpp): travel_x_mm/travel_y_mm/travel_z_mm = [min, max],
// max_feed_mm_min, max_accel_mm_s2. Always strict, in run.toml too: a mistyped limit must
// not fall back to the default it was meant to change.
dsp::WorkEnvelope read_envelope(StrictTable t, const dsp::WorkEnvelope& defaults = {});

}  // namespace eical::drivers
