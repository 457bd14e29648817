#include "drivers/import/capture_files.hpp"

#include "drivers/config/extension_names.hpp"
#include "drivers/run_io/line_source.hpp"
#include "drivers/run_io/run_writer.hpp"
#include "drivers/source/servo_stream.hpp"
#include "dsp/core/error.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <string_view>

namespace eical::drivers {
namespace {

std::string where(const LineSource& src) { return src.name() + ":" + std::to_string(src.line_number()); }

[[noreturn]] void fail(const LineSource& src, const std::string& why) {
  throw dsp::InputError(where(src) + ": " + why);
}
[[noreturn]] void fail_column(const LineSource& src, const std::string& column, const std::string& why) {
  throw dsp::InputError(where(src) + ": column '" + column + "': " + why);
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  if (s.size() >= 2 && s.front() == '"' && s.back() == '"') s = s.substr(1, s.size() - 2);
  return s;
}

void split(std::string_view line, std::vector<std::string_view>& out) {
  out.clear();
  std::size_t pos = 0;
  for (;;) {
    const auto comma = line.find(',', pos);
    out.push_back(trim(line.substr(pos, comma == std::string_view::npos ? std::string_view::npos : comma - pos)));
    if (comma == std::string_view::npos) return;
    pos = comma + 1;
  }
}

double number(const LineSource& src, const std::string& column, std::string_view f) {
  if (f.empty()) fail_column(src, column, "empty field");
  if (f.front() == '+') f.remove_prefix(1);
  double v = 0.0;
  const auto [p, ec] = std::from_chars(f.data(), f.data() + f.size(), v);
  if (ec != std::errc() || p != f.data() + f.size())
    fail_column(src, column, "expected a number, got '" + std::string(f) + "'");
  if (!std::isfinite(v)) fail_column(src, column, "NaN or Inf ('" + std::string(f) + "')");
  return v;
}

// Data lines of a CSV: blank lines are allowed at the end only; time must increase.
template <class Row>
void read_rows(LineSource& src, std::size_t n_fields, const std::string& time_column, std::vector<double>& t_s,
               Row&& row) {
  std::string_view line;
  std::vector<std::string_view> fields;
  std::size_t blank_at = 0;
  while (src.next(line)) {
    if (trim(line).empty()) {
      if (!blank_at) blank_at = src.line_number();
      continue;
    }
    if (blank_at) throw dsp::InputError(src.name() + ":" + std::to_string(blank_at) + ": blank line inside the data");
    split(line, fields);
    if (fields.size() != n_fields)
      fail(src, (src.last_line_had_newline() ? std::string("wrong number of fields (")
                                             : std::string("truncated file: the last line is incomplete (")) +
                    std::to_string(fields.size()) + ", header has " + std::to_string(n_fields) + ")");
    const double t = row(fields);
    if (!t_s.empty() && !(t > t_s.back())) {
      char buf[96];
      std::snprintf(buf, sizeof buf, "time does not increase (%.9g s after %.9g s)", t, t_s.back());
      fail_column(src, time_column, buf);
    }
    t_s.push_back(t);
  }
  if (t_s.empty()) throw dsp::InputError(src.name() + ": no samples after the header");
}

// Column indices for `cols` in a header, or the positions 0..3 when names are empty.
std::array<std::size_t, 4> resolve(const LineSource& src, const std::vector<std::string_view>& header,
                                   const CsvColumns& cols) {
  const std::array<std::string, 4> names = {cols.time, cols.values[0], cols.values[1], cols.values[2]};
  std::array<std::size_t, 4> at{};
  std::string list;
  for (auto h : header) list += (list.empty() ? "" : ", ") + std::string(h);
  for (std::size_t k = 0; k < 4; ++k) {
    if (names[k].empty()) {
      if (k >= header.size())
        fail(src, "header has " + std::to_string(header.size()) + " columns, 4 needed (time and three values)");
      at[k] = k;
      continue;
    }
    std::size_t found = header.size();
    for (std::size_t c = 0; c < header.size(); ++c)
      if (header[c] == names[k]) {
        if (found != header.size()) fail(src, "column '" + names[k] + "' appears twice");
        found = c;
      }
    if (found == header.size()) fail(src, "no column '" + names[k] + "' (the header has: " + list + ")");
    at[k] = found;
  }
  const auto listed = [&](std::string_view h) {
    return std::find(cols.ignored.begin(), cols.ignored.end(), h) != cols.ignored.end();
  };
  for (const auto& name : cols.ignored)
    if (std::find(header.begin(), header.end(), name) == header.end())
      fail(src, "column '" + name + "' is to be ignored, but the header has no such column (it has: " + list + ")");
  for (std::size_t c = 0; c < header.size(); ++c)
    if (std::find(at.begin(), at.end(), c) == at.end() && !listed(header[c]) && !is_extension_name(header[c]))
      fail_column(src, std::string(header[c]),
                  "unknown column: neither read (time '" + std::string(header[at[0]]) + "', values '" +
                      std::string(header[at[1]]) + "', '" + std::string(header[at[2]]) + "', '" +
                      std::string(header[at[3]]) + "') nor listed as ignored");
  return at;
}

struct Csv {
  std::vector<double> t;
  std::vector<Eigen::Vector3d> v;
  std::string source;
};

Csv read_csv(const std::filesystem::path& file, const CsvColumns& cols, double value_scale) {
  if (!std::filesystem::exists(file)) throw dsp::InputError(file.string() + ": no such file");
  LineSource src(file);
  std::string_view line;
  if (!src.next(line)) throw dsp::InputError(file.string() + ": empty file (no header line)");
  std::vector<std::string_view> header;
  split(line, header);
  std::vector<std::string> header_copy(header.begin(), header.end());
  std::vector<std::string_view> header_views(header_copy.begin(), header_copy.end());
  const auto at = resolve(src, header_views, cols);
  if (!(cols.time_scale_s > 0.0)) throw dsp::InputError(file.string() + ": the time unit must be positive");
  Csv out;
  out.source = file.string();
  read_rows(src, header_copy.size(), header_copy[at[0]], out.t, [&](const std::vector<std::string_view>& f) {
    Eigen::Vector3d v;
    for (int a = 0; a < 3; ++a)
      v[a] = number(src, header_copy[at[static_cast<std::size_t>(a + 1)]], f[at[static_cast<std::size_t>(a + 1)]]) *
             value_scale;
    out.v.push_back(v);
    return number(src, header_copy[at[0]], f[at[0]]) * cols.time_scale_s;
  });
  return out;
}

void write_lines(const std::filesystem::path& file, const std::string& text) { write_text_atomic(file, text); }

}  // namespace

double accel_unit_in_mps2(AccelUnit unit) {
  switch (unit) {
    case AccelUnit::mps2: return 1.0;
    case AccelUnit::mmps2: return 1e-3;
    case AccelUnit::g: return kStandardGravity_mps2;
  }
  return 1.0;
}

StampedAccel read_klipper_capture(const std::filesystem::path& file) {
  if (!std::filesystem::exists(file)) throw dsp::InputError(file.string() + ": no such file");
  LineSource src(file);
  std::string_view line;
  bool header = false;
  while (!header && src.next(line)) {
    if (line.rfind("##", 0) == 0) continue;  // older Klipper: "##<stats>" before the header
    if (line != "#time,accel_x,accel_y,accel_z")
      fail(src, "expected Klipper's header '#time,accel_x,accel_y,accel_z', got '" + std::string(line) + "'");
    header = true;
  }
  if (!header) throw dsp::InputError(file.string() + ": empty file (no '#time,accel_x,accel_y,accel_z' header)");
  StampedAccel out;
  out.source = file.string();
  static const std::string names[4] = {"time", "accel_x", "accel_y", "accel_z"};
  const double to_mps2 = accel_unit_in_mps2(AccelUnit::mmps2);
  read_rows(src, 4, names[0], out.t_s, [&](const std::vector<std::string_view>& f) {
    out.accel_mps2.emplace_back(number(src, names[1], f[1]) * to_mps2, number(src, names[2], f[2]) * to_mps2,
                                number(src, names[3], f[3]) * to_mps2);
    return number(src, names[0], f[0]);
  });
  return out;
}

void write_klipper_capture(const std::filesystem::path& file, const StampedAccel& capture) {
  std::string out = "#time,accel_x,accel_y,accel_z\n";
  char buf[160];
  for (std::size_t k = 0; k < capture.t_s.size(); ++k) {
    const Eigen::Vector3d a = capture.accel_mps2[k] * 1e3;
    std::snprintf(buf, sizeof buf, "%.6f,%.6f,%.6f,%.6f\n", capture.t_s[k], a.x(), a.y(), a.z());
    out += buf;
  }
  write_lines(file, out);
}

StampedAccel read_accel_csv(const std::filesystem::path& file, const CsvColumns& columns, AccelUnit unit) {
  Csv csv = read_csv(file, columns, accel_unit_in_mps2(unit));
  return {std::move(csv.source), std::move(csv.t), std::move(csv.v)};
}

void write_accel_csv(const std::filesystem::path& file, const StampedAccel& capture, AccelUnit unit) {
  std::string out = "t,ax,ay,az\n";
  char buf[160];
  const double per_mps2 = 1.0 / accel_unit_in_mps2(unit);
  for (std::size_t k = 0; k < capture.t_s.size(); ++k) {
    const Eigen::Vector3d a = capture.accel_mps2[k] * per_mps2;
    std::snprintf(buf, sizeof buf, "%.9f,%.9g,%.9g,%.9g\n", capture.t_s[k], a.x(), a.y(), a.z());
    out += buf;
  }
  write_lines(file, out);
}

NcTrace read_halsampler(const std::filesystem::path& file, double servo_period_s) {
  if (!(servo_period_s > 0.0)) throw dsp::InputError(file.string() + ": the servo period must be positive");
  if (!std::filesystem::exists(file)) throw dsp::InputError(file.string() + ": no such file");
  LineSource src(file);
  std::string_view line;
  NcTrace out;
  out.source = file.string();
  std::string error;
  std::int64_t last = -1;
  while (src.next(line)) {
    const auto parsed = parse_servo_line(line, error);
    if (!parsed) fail(src, error);
    if (parsed->kind == ServoLine::Kind::overrun) continue;  // the sample numbers jump over what was lost
    const ServoSample& s = parsed->sample;
    if (s.number <= last)
      fail(src,
           "sample number " + std::to_string(s.number) + " does not increase (after " + std::to_string(last) + ")");
    last = s.number;
    out.t_s.push_back(static_cast<double>(s.number) * servo_period_s);
    out.pos_mm.emplace_back(s.cmd_mm[0], s.cmd_mm[1], s.cmd_mm[2]);
  }
  if (out.t_s.empty()) throw dsp::InputError(file.string() + ": empty file (no servo samples)");
  return out;
}

void write_halsampler(const std::filesystem::path& file, const NcTrace& trace, std::int64_t first_number) {
  std::string out;
  char buf[256];
  for (std::size_t k = 0; k < trace.pos_mm.size(); ++k) {
    const Eigen::Vector3d& p = trace.pos_mm[k];
    std::snprintf(buf, sizeof buf, "%lld %f %f %f %f %f %f 0\n",
                  static_cast<long long>(first_number + static_cast<std::int64_t>(k)), p.x(), p.y(), p.z(), p.x(),
                  p.y(), p.z());
    out += buf;
  }
  write_lines(file, out);
}

NcTrace read_nc_csv(const std::filesystem::path& file, const CsvColumns& columns) {
  Csv csv = read_csv(file, columns, 1.0);
  return {std::move(csv.source), std::move(csv.t), std::move(csv.v)};
}

void write_nc_csv(const std::filesystem::path& file, const NcTrace& trace) {
  std::string out = "t,x,y,z\n";
  char buf[160];
  for (std::size_t k = 0; k < trace.t_s.size(); ++k) {
    std::snprintf(buf, sizeof buf, "%.9f,%.9f,%.9f,%.9f\n", trace.t_s[k], trace.pos_mm[k].x(), trace.pos_mm[k].y(),
                  trace.pos_mm[k].z());
    out += buf;
  }
  write_lines(file, out);
}

}  // namespace eical::drivers
