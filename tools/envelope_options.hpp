#pragma once
// The machine's work envelope (dsp/core/work_envelope.hpp) on the command line of gen-nc,
// simulate and plan: --envelope FILE (its [envelope] table: eicald.toml, a run's run.toml,
// a scenario), then --travel-x/-y/-z MIN,MAX, --max-feed and --max-accel over it.
#include "dsp/core/work_envelope.hpp"
#include "sim/nc/set_point.hpp"

#include <CLI/CLI.hpp>

#include <optional>
#include <string>
#include <vector>

namespace eical::tools {

struct EnvelopeOptions {
  std::string file;
  std::vector<double> travel_mm[3];  // empty: not given
  std::optional<double> max_feed_mm_min, max_accel_mm_s2;
};

void add_envelope_options(CLI::App& cmd, EnvelopeOptions& o);

// `base` (the default, or what the scenario says), FILE's [envelope] over it, the options
// over that. Throws InputError naming the option or the file's key.
dsp::WorkEnvelope envelope_of(const EnvelopeOptions& o, const dsp::WorkEnvelope& base = {});

// "<what>: the program reaches x = 100000 mm, beyond the x travel -500..500 mm (--travel-x;
// [envelope] travel_x_mm)" when the set-point leaves the envelope; nullopt when it stays.
std::optional<std::string> envelope_refusal(const sim::nc::SetPoint& set_point, const dsp::WorkEnvelope& envelope,
                                            const std::string& what);
// The same, thrown as InputError.
void require_within(const sim::nc::SetPoint& set_point, const dsp::WorkEnvelope& envelope, const std::string& what);

}  // namespace eical::tools
