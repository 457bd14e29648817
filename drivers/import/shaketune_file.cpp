#include "drivers/import/shaketune_file.hpp"

#include "dsp/core/error.hpp"

#include <zstd.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <memory>

namespace eical::drivers {
namespace {

std::string read_bytes(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw dsp::InputError(file.string() + ": cannot be read");
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// Every frame of the stream (a writer may flush several), however it was written: the
// plugin's stream writer leaves the content size out of the frame header. The decoder keeps
// a frame's last input byte until it has given out all of the frame's output, so the input
// running out with a frame open (last ≠ 0) is a cut-short file.
std::string decompress(const std::string& packed, const std::string& source) {
  const std::unique_ptr<ZSTD_DCtx, decltype(&ZSTD_freeDCtx)> ctx(ZSTD_createDCtx(), &ZSTD_freeDCtx);
  if (!ctx) throw dsp::InputError(source + ": zstd: out of memory");
  std::string out;
  std::string chunk(ZSTD_DStreamOutSize(), '\0');
  ZSTD_inBuffer in{packed.data(), packed.size(), 0};
  std::size_t last = 0;
  while (in.pos < in.size) {
    ZSTD_outBuffer o{chunk.data(), chunk.size(), 0};
    last = ZSTD_decompressStream(ctx.get(), &o, &in);
    if (ZSTD_isError(last))
      throw dsp::InputError(source + ": not a Shake&Tune .stdata file (a zstd stream): " + ZSTD_getErrorName(last));
    out.append(chunk.data(), o.pos);
  }
  if (packed.empty() || last != 0) throw dsp::InputError(source + ": the zstd stream ends inside a frame (truncated)");
  return out;
}

ShakeTuneMeasurement measurement_of(const nlohmann::json& j, const std::string& where, const std::string& file) {
  if (!j.is_object() || !j.contains("name") || !j["name"].is_string() || !j.contains("samples") ||
      !j["samples"].is_array())
    throw dsp::InputError(where + ": a measurement is {\"name\": text, \"samples\": [[t, ax, ay, az], ...]}");
  ShakeTuneMeasurement m;
  m.name = j["name"].get<std::string>();
  m.capture.source = file + "#" + m.name;
  const auto& samples = j["samples"];
  m.capture.t_s.reserve(samples.size());
  m.capture.accel_mps2.reserve(samples.size());
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const auto& s = samples[i];
    const std::string at = where + ": measurement '" + m.name + "', sample " + std::to_string(i);
    if (!s.is_array() || s.size() != 4)
      throw dsp::InputError(at + ": a sample is [time s, accel_x, accel_y, accel_z mm/s2]");
    double v[4];
    for (int k = 0; k < 4; ++k) {
      if (!s[k].is_number()) throw dsp::InputError(at + ": value " + std::to_string(k) + " is not a number");
      v[k] = s[k].get<double>();
      if (!std::isfinite(v[k])) throw dsp::InputError(at + ": value " + std::to_string(k) + " is not finite");
    }
    if (!m.capture.t_s.empty() && v[0] <= m.capture.t_s.back())
      throw dsp::InputError(at + ": time " + std::to_string(v[0]) + " s does not follow " +
                            std::to_string(m.capture.t_s.back()) + " s");
    m.capture.t_s.push_back(v[0]);
    m.capture.accel_mps2.emplace_back(v[1] * 1e-3, v[2] * 1e-3, v[3] * 1e-3);
  }
  return m;
}

}  // namespace

std::vector<ShakeTuneMeasurement> read_shaketune_stdata(const std::filesystem::path& file) {
  const std::string source = file.string();
  const std::string text = decompress(read_bytes(file), source);
  // Python's pickle starts with PROTO (0x80); JSON text never does.
  if (!text.empty() && static_cast<unsigned char>(text.front()) == 0x80)
    throw dsp::InputError(source +
                          ": an early Shake&Tune .stdata (a Python pickle), which eical does not read: unpickling "
                          "runs code the file names. Update Shake&Tune and measure again (its .stdata is now JSON "
                          "lines), or record the test with TEST_RESONANCES ... OUTPUT=raw_data and use "
                          "'eical import klipper'");
  std::vector<ShakeTuneMeasurement> out;
  std::size_t line_no = 0, begin = 0;
  while (begin < text.size()) {
    std::size_t end = text.find('\n', begin);
    if (end == std::string::npos) end = text.size();
    ++line_no;
    const std::string_view line(text.data() + begin, end - begin);
    begin = end + 1;
    if (line.find_first_not_of(" \t\r") == std::string_view::npos) continue;
    const std::string where = source + ":" + std::to_string(line_no);
    nlohmann::json j;
    try {
      j = nlohmann::json::parse(line);
    } catch (const nlohmann::json::exception& e) {  // parse_error, and out_of_range for a number like 1e2500
      throw dsp::InputError(where + ": not JSON (" + e.what() + ")");
    }
    out.push_back(measurement_of(j, where, source));
  }
  if (out.empty()) throw dsp::InputError(source + ": the file holds no measurement");
  return out;
}

void write_shaketune_stdata(const std::filesystem::path& file, const std::vector<ShakeTuneMeasurement>& measurements) {
  std::string text;
  for (const auto& m : measurements) {
    nlohmann::json samples = nlohmann::json::array();
    for (std::size_t i = 0; i < m.capture.t_s.size(); ++i) {
      const Eigen::Vector3d& a = m.capture.accel_mps2[i];
      samples.push_back({m.capture.t_s[i], a.x() * 1e3, a.y() * 1e3, a.z() * 1e3});
    }
    text += nlohmann::json{{"name", m.name}, {"samples", samples}}.dump() + "\n";
  }
  std::string packed(ZSTD_compressBound(text.size()), '\0');
  const std::size_t n = ZSTD_compress(packed.data(), packed.size(), text.data(), text.size(), 3);
  if (ZSTD_isError(n)) throw dsp::InputError(file.string() + ": zstd: " + ZSTD_getErrorName(n));
  std::ofstream out(file, std::ios::binary);
  out.write(packed.data(), static_cast<std::streamsize>(n));
  if (!out) throw dsp::InputError(file.string() + ": cannot be written");
}

const ShakeTuneMeasurement& pick_measurement(const std::vector<ShakeTuneMeasurement>& measurements,
                                             const std::string& name, const std::string& source) {
  if (name.empty() && measurements.size() == 1) return measurements.front();
  for (const auto& m : measurements)
    if (m.name == name) return m;
  std::string names;
  for (const auto& m : measurements) {
    char b[64];
    const double span_s = m.capture.t_s.size() > 1 ? m.capture.t_s.back() - m.capture.t_s.front() : 0.0;
    std::snprintf(b, sizeof b, " (%zu samples, %.4g s)", m.capture.t_s.size(), span_s);
    names += (names.empty() ? "" : ", ") + m.name + b;
  }
  throw dsp::InputError(
      source +
      (name.empty() ? ": holds " + std::to_string(measurements.size()) + " measurements, name one with --measurement: "
                    : ": no measurement '" + name + "'; it holds: ") +
      names);
}

}  // namespace eical::drivers
