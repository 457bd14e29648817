#pragma once
// quality.verdict of a result, as a type: what a run's figures are worth as a measurement
// (verdict.hpp decides it). The name is rendered at the edges (JSON, text, report, history).
#include <cstdint>
#include <optional>
#include <string_view>

namespace eical::dsp {

enum class Verdict : std::uint8_t {
  ok,              // the figures are results, each with its U
  degraded,        // a flag limits or invalidates the measurement (the reasons name it)
  not_measurable,  // U exceeds what the program must resolve, or nothing holds the position
};

[[nodiscard]] constexpr const char* verdict_name(Verdict v) noexcept {
  switch (v) {
    case Verdict::ok: return "ok";
    case Verdict::degraded: return "degraded";
    case Verdict::not_measurable: return "not_measurable";
  }
  return "ok";
}

[[nodiscard]] constexpr std::optional<Verdict> verdict_from_name(std::string_view s) noexcept {
  for (Verdict v : {Verdict::ok, Verdict::degraded, Verdict::not_measurable})
    if (s == verdict_name(v)) return v;
  return std::nullopt;
}

}  // namespace eical::dsp
