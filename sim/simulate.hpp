#pragma once
// A synthetic recorded run from a scenario: NC interpolator → machine (v1: ideal, the
// relative motion is the set-point; table axes move the table by −p, head axes the head
// by +p) → per sensor specific force (gravity, mounting) → PT2 at the internal rate →
// DAQ group delay → static model (6-4) with noise → 24-bit ADC.
//
// Conventions the DSP pipeline relies on:
//  * specific force f = a − g_vec with g_vec = (0, 0, −g): a sensor at rest, z up, reads +1 g;
//  * sensor axes = to_machine⁻¹ · f (to_machine maps sensor axes to machine axes);
//  * U = k1 (a_g + bias + k2 a_g² + k3 a_g³ + n), counts = round(U / lsb) + offset;
//  * output sample n holds the analog signal at n/fs − d/fs (d = DAQ group delay in
//    samples); cmd_mm and ref_mm at sample n are the set-point and true relative position
//    at n/fs (not delayed); triggers sit on the sample nearest their time.
// Deterministic for a given seed: std::mt19937_64 and std::normal_distribution of
// libstdc++ (the same build always gives the same frames).
#include "dsp/core/run.hpp"
#include "sim/scenario.hpp"

namespace eical::sim {

dsp::Run simulate(const Scenario& scenario);

}  // namespace eical::sim
