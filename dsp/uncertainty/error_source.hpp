#pragma once
// The sources of a measurement's error the uncertainty's draws are made of
// (error_field.hpp), as a type: what `eical analyze --budget` switches on one at a time to
// show each source's share of a figure's U.
#include <array>
#include <cstdint>

namespace eical::dsp::uncertainty {

enum class ErrorSource : std::uint8_t {
  integration,         // the sensors' white noise (as measured at rest) and bias between the supports
  sensor_scale,        // scale, mounting and cross terms of both sensors (E), data sheet or calibration
  sensor_timing,       // the PT2's damping term and the DAQ's delay (v·τ)
  temperature,         // the bias' temperature coefficient over the run's case temperatures
  strip_offset,        // each PSD strip's own offset: its position calibration
  strip_nonlinearity,  // each PSD strip's nonlinearity within the data sheet's bound
};

inline constexpr std::array<ErrorSource, 6> kErrorSources = {
    ErrorSource::integration, ErrorSource::sensor_scale, ErrorSource::sensor_timing,
    ErrorSource::temperature, ErrorSource::strip_offset, ErrorSource::strip_nonlinearity};

// JSON key ("integration", ...) and the words a reader reads.
[[nodiscard]] constexpr const char* error_source_key(ErrorSource s) noexcept {
  switch (s) {
    case ErrorSource::integration: return "integration";
    case ErrorSource::sensor_scale: return "sensor_scale";
    case ErrorSource::sensor_timing: return "sensor_timing";
    case ErrorSource::temperature: return "temperature";
    case ErrorSource::strip_offset: return "strip_offset";
    case ErrorSource::strip_nonlinearity: return "strip_nonlinearity";
  }
  return "integration";
}
[[nodiscard]] constexpr const char* error_source_words(ErrorSource s) noexcept {
  switch (s) {
    case ErrorSource::integration: return "integration noise between the supports";
    case ErrorSource::sensor_scale: return "sensor scale and mounting";
    case ErrorSource::sensor_timing: return "sensor damping and DAQ delay";
    case ErrorSource::temperature: return "bias temperature coefficient";
    case ErrorSource::strip_offset: return "PSD strip offsets (position calibration)";
    case ErrorSource::strip_nonlinearity: return "PSD strip nonlinearity";
  }
  return "";
}

// Which sources a draw includes.
struct SourceMask {
  std::uint32_t bits = 0xFFFFFFFFu;
  [[nodiscard]] constexpr bool has(ErrorSource s) const noexcept { return (bits >> static_cast<unsigned>(s)) & 1u; }
  [[nodiscard]] static constexpr SourceMask only(ErrorSource s) noexcept { return {1u << static_cast<unsigned>(s)}; }
};

}  // namespace eical::dsp::uncertainty
