#include "tools/envelope_options.hpp"

#include "drivers/config/meta_sections.hpp"
#include "drivers/config/strict_toml.hpp"
#include "dsp/core/error.hpp"
#include "sim/nc/envelope_check.hpp"

#include <cmath>

namespace eical::tools {
namespace {

constexpr const char* kTravelOption[3] = {"--travel-x", "--travel-y", "--travel-z"};

const char* option_of(const sim::nc::EnvelopeExcess& x) {
  switch (x.limit) {
    case sim::nc::EnvelopeLimit::travel: return kTravelOption[x.axis];
    case sim::nc::EnvelopeLimit::feed: return "--max-feed";
    case sim::nc::EnvelopeLimit::accel: return "--max-accel";
  }
  return "";
}

}  // namespace

void add_envelope_options(CLI::App& cmd, EnvelopeOptions& o) {
  const std::string group = "Work envelope (default: 1000 x 600 x 600 mm about the program's origin, 30 m/min, 1 g)";
  cmd.add_option("--envelope", o.file,
                 "the machine's work envelope: the [envelope] table of this TOML file (eicald.toml, a run.toml)")
      ->check(CLI::ExistingFile)
      ->group(group);
  for (int i = 0; i < 3; ++i)
    cmd.add_option(kTravelOption[i], o.travel_mm[i],
                   std::string("travel of ") + static_cast<char>('x' + i) + ", MIN,MAX in mm (program coordinates)")
        ->expected(2)
        ->delimiter(',')
        ->group(group);
  cmd.add_option("--max-feed", o.max_feed_mm_min, "the machine's maximum path speed, mm/min (rapid moves included)")
      ->check(CLI::PositiveNumber)
      ->group(group);
  cmd.add_option("--max-accel", o.max_accel_mm_s2,
                 "the machine's maximum path acceleration, mm/s^2 (centripetal included; 9810 = 1 g)")
      ->check(CLI::PositiveNumber)
      ->group(group);
}

dsp::WorkEnvelope envelope_of(const EnvelopeOptions& o, const dsp::WorkEnvelope& base) {
  dsp::WorkEnvelope e = base;
  if (!o.file.empty()) {
    const toml::table root = drivers::StrictTable::parse_file(o.file);
    drivers::StrictTable t(root, o.file, "");
    auto env = t.optional_table("envelope");
    if (!env) throw dsp::InputError(o.file + ": no [envelope] table (--envelope)");
    e = drivers::read_envelope(*env, e);
  }
  for (int i = 0; i < 3; ++i) {
    const auto& v = o.travel_mm[i];
    if (v.empty()) continue;
    if (v.size() != 2 || !(v[0] < v[1]) || !std::isfinite(v[0]) || !std::isfinite(v[1]))
      throw dsp::InputError(std::string(kTravelOption[i]) + ": MIN,MAX in mm with MIN below MAX");
    e.travel_mm[i][0] = v[0], e.travel_mm[i][1] = v[1];
  }
  if (o.max_feed_mm_min) e.max_feed_mm_min = *o.max_feed_mm_min;
  if (o.max_accel_mm_s2) e.max_accel_mm_s2 = *o.max_accel_mm_s2;
  return e;
}

std::optional<std::string> envelope_refusal(const sim::nc::SetPoint& set_point, const dsp::WorkEnvelope& envelope,
                                            const std::string& what) {
  const auto x = sim::nc::envelope_excess(set_point, envelope);
  if (!x) return std::nullopt;
  return what + ": " + sim::nc::describe(*x, envelope) + " (" + option_of(*x) + "; [envelope] " +
         sim::nc::envelope_key(*x) + ")";
}

void require_within(const sim::nc::SetPoint& set_point, const dsp::WorkEnvelope& envelope, const std::string& what) {
  if (auto why = envelope_refusal(set_point, envelope, what)) throw dsp::InputError(*why);
}

}  // namespace eical::tools
