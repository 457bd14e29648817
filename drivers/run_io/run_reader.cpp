#include "drivers/run_io/run_reader.hpp"

#include "drivers/config/meta_sections.hpp"
#include "drivers/config/strict_toml.hpp"
#include "drivers/run_io/line_source.hpp"
#include "dsp/core/error.hpp"
#include "dsp/core/frame_fields.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>

namespace eical::drivers {
namespace fs = std::filesystem;
namespace {

// No case temperature of a working sensor is beyond this; a float could not hold 1e300.
constexpr double kMaxTemp_c = 1000.0;

enum Col : int {
  c_t,
  c_tax,
  c_tay,
  c_taz,
  c_hax,
  c_hay,
  c_haz,
  c_ttemp,
  c_htemp,
  c_cx,
  c_cy,
  c_cz,
  c_rx,
  c_ry,
  c_rz,
  c_trig,
  c_psd0,  // psd k i1 = c_psd0 + 2k, i2 = c_psd0 + 2k + 1
  c_count = c_psd0 + 2 * dsp::kMaxPsd
};

const char* const kNames[] = {"t",       "table_ax",   "table_ay",  "table_az", "head_ax", "head_ay",
                              "head_az", "table_temp", "head_temp", "cmd_x",    "cmd_y",   "cmd_z",
                              "ref_x",   "ref_y",      "ref_z",     "trigger"};

std::string column_name(int c) {
  if (c < c_psd0) return kNames[c];
  const int k = (c - c_psd0) / 2;
  return "psd" + std::to_string(k) + ((c - c_psd0) % 2 == 0 ? "_i1" : "_i2");
}

[[noreturn]] void fail_at(const LineSource& src, int col, const std::string& what) {
  throw dsp::InputError(src.name() + ":" + std::to_string(src.line_number()) + ": column '" + column_name(col) +
                        "': " + what);
}

std::optional<double> parse_double(const LineSource& src, int col, std::string_view f) {
  if (f.empty()) return std::nullopt;
  double v = 0.0;
  const auto [p, ec] = std::from_chars(f.data(), f.data() + f.size(), v);
  if (ec != std::errc() || p != f.data() + f.size())
    fail_at(src, col, "expected a number, got '" + std::string(f) + "'");
  if (!std::isfinite(v)) fail_at(src, col, "NaN or Inf in a sample ('" + std::string(f) + "')");
  return v;
}

std::optional<std::int64_t> parse_int(const LineSource& src, int col, std::string_view f, const char* what) {
  if (f.empty()) return std::nullopt;
  std::int64_t v = 0;
  const auto [p, ec] = std::from_chars(f.data(), f.data() + f.size(), v);
  if (ec == std::errc::result_out_of_range)
    fail_at(src, col, std::string(what) + " out of range: '" + std::string(f) + "'");
  if (ec != std::errc() || p != f.data() + f.size())
    fail_at(src, col, std::string("expected ") + what + ", got '" + std::string(f) + "'");
  return v;
}

// The stages of SampleReader::next(), one row: its fields, then each group of columns into
// the frame (in the file's column order, so the first bad field is the one reported).

// Splits line into its fields; exactly n_fields (the header's) or an error naming the line.
void split_fields(const LineSource& src, const fs::path& file, int n_fields, std::string_view line,
                  std::vector<std::string_view>& fields) {
  std::size_t k = 0, pos = 0;
  for (;;) {
    const auto comma = line.find(',', pos);
    if (k < fields.size())
      fields[k] = line.substr(pos, comma == std::string_view::npos ? std::string_view::npos : comma - pos);
    ++k;
    if (comma == std::string_view::npos) break;
    pos = comma + 1;
  }
  if (k != fields.size()) {
    const std::string why =
        !src.last_line_had_newline() ? "truncated file: the last line is incomplete" : "wrong number of fields";
    throw dsp::InputError(file.string() + ":" + std::to_string(src.line_number()) + ": " + why + " (" +
                          std::to_string(k) + " fields, header has " + std::to_string(n_fields) + ")");
  }
}

// A row split into fields, and where each column is among them.
struct Row {
  const LineSource& src;
  const std::vector<std::string_view>& fields;
  const int* where;  // column -> field (-1: not in the file)
  [[nodiscard]] std::string_view field(int c) const { return fields[static_cast<std::size_t>(where[c])]; }
};

// t: the sample index on the grid of fs_hz, after the previous row's (a gap flagged).
void read_time(const Row& row, double fs, std::int64_t& prev_index, dsp::Frame& f) {
  const auto t = parse_double(row.src, c_t, row.field(c_t));
  if (!t) fail_at(row.src, c_t, "empty time");
  const double idx_real = *t * fs;
  const auto idx = static_cast<std::int64_t>(std::llround(idx_real));
  // 1e-3 sample, plus what printing t with 10 significant digits can cost on long runs.
  if (std::abs(idx_real - static_cast<double>(idx)) > 1e-3 + 1e-9 * std::abs(idx_real))
    fail_at(
        row.src, c_t,
        "time " + std::string(row.field(c_t)) + " s is not on the sample grid of fs = " + std::to_string(fs) + " Hz");
  if (prev_index >= 0 && idx <= prev_index) fail_at(row.src, c_t, "time does not increase");
  if (prev_index >= 0 && idx > prev_index + 1) f.flags |= dsp::frame_flag::gap_before;
  prev_index = idx;
  f.sample_index = idx;
}

// The six accelerometer channels in ADC counts; full: the ADC's full scale in counts.
void read_accel(const Row& row, double full, dsp::Frame& f) {
  for (int c = c_tax; c <= c_haz; ++c) {
    const auto v = parse_int(row.src, c, row.field(c), "integer ADC counts");
    if (!v) {
      f.flags |= dsp::frame_flag::accel_missing | dsp::frame_flag::sensor_missing(c - c_tax < 3 ? 0 : 1) |
                 dsp::frame_flag::accel_field_missing(c - c_tax);
      continue;
    }
    if (*v > INT32_MAX || *v < INT32_MIN) fail_at(row.src, c, "ADC counts out of the 32-bit range");
    f.accel_counts[c - c_tax] = static_cast<std::int32_t>(*v);
    if (static_cast<double>(*v) >= full - 1 || static_cast<double>(*v) <= -full)
      f.flags |= dsp::frame_flag::accel_saturated;
  }
}

// The case temperatures of table and head.
void read_temperatures(const Row& row, dsp::Frame& f) {
  for (int s = 0; s < 2; ++s) {
    const auto v = parse_double(row.src, c_ttemp + s, row.field(c_ttemp + s));
    // Checked before the conversion to float (beyond its range it is undefined).
    if (v && !(std::abs(*v) <= kMaxTemp_c))
      fail_at(row.src, c_ttemp + s, "temperature beyond +-1000 C ('" + std::string(row.field(c_ttemp + s)) + "')");
    if (v)
      f.temp_c[s] = static_cast<float>(*v);
    else
      f.flags |= dsp::frame_flag::temp_missing;
  }
}

// The set-point and, where the file has it, the reference position, axis by axis.
void read_positions(const Row& row, dsp::Frame& f) {
  for (int a = 0; a < 3; ++a) {
    const auto v = parse_double(row.src, c_cx + a, row.field(c_cx + a));
    if (v)
      f.cmd_mm[a] = *v;
    else
      f.flags |= dsp::frame_flag::cmd_missing;
    if (row.where[c_rx + a] >= 0) {
      const auto r = parse_double(row.src, c_rx + a, row.field(c_rx + a));
      if (r) f.ref_mm[a] = *r;
    }
  }
}

// The PSD strips' electrode voltages, back to ADC counts (lsb volts a count, offset counts).
void read_psd_counts(const Row& row, int n_psd, double lsb, double offset, dsp::Frame& f) {
  for (int c = c_psd0; c < c_psd0 + 2 * n_psd; ++c) {
    const auto v = parse_double(row.src, c, row.field(c));
    if (!v) {
      dsp::frame_flag::mark_psd_field_missing(f, c - c_psd0);
      continue;
    }
    const double counts = *v / lsb + offset;
    if (!(std::abs(counts) <= INT32_MAX))
      fail_at(row.src, c, "PSD value beyond the ADC's 32-bit range ('" + std::string(row.field(c)) + "')");
    f.psd_counts[c - c_psd0] = static_cast<std::int32_t>(std::llround(counts));
  }
}

// The trigger code (0: none); an empty field is an error.
void read_trigger(const Row& row, dsp::Frame& f) {
  const auto trig = parse_int(row.src, c_trig, row.field(c_trig), "an integer trigger code");
  if (!trig) fail_at(row.src, c_trig, "empty trigger (0 means none)");
  f.trigger = static_cast<std::int32_t>(*trig);
}

}  // namespace

SampleReader::SampleReader(const fs::path& file, const dsp::RunMeta& meta, dsp::ChannelPresence& channels)
    : src_(std::make_unique<LineSource>(file)), file_(file), meta_(meta) {
  std::string_view line;
  if (!src_->next(line)) throw dsp::InputError(file.string() + ": empty file (no header line)");
  where_.fill(-1);
  n_fields_ = 0;
  std::string unknown;  // the first column eical does not know
  {
    std::size_t pos = 0;
    for (;;) {
      const auto comma = line.find(',', pos);
      const std::string_view name =
          line.substr(pos, comma == std::string_view::npos ? std::string_view::npos : comma - pos);
      bool known = false;
      for (int c = 0; c < c_count; ++c)
        if (column_name(c) == name) {
          if (where_[c] >= 0)
            throw dsp::InputError(file.string() + ":1: column '" + std::string(name) + "' appears twice");
          where_[c] = n_fields_;
          known = true;
        }
      // As run.toml's keys: a misspelt column (ref_X) is refused, never read as absent.
      if (!known && !is_extension_name(name) && unknown.empty()) unknown = name;
      ++n_fields_;
      if (comma == std::string_view::npos) break;
      pos = comma + 1;
    }
  }
  // A misspelt column is usually also a missing one: both are said.
  const std::string unknown_text =
      unknown.empty()
          ? std::string()
          : "column '" + unknown + "': unknown column (check the spelling; another tool's columns begin with " +
                std::string(kExtensionPrefix) + ")";
  const auto also_unknown = [&] { return unknown.empty() ? std::string() : "; " + unknown_text; };
  for (int c : {c_t, c_tax, c_tay, c_taz, c_hax, c_hay, c_haz, c_ttemp, c_htemp, c_cx, c_cy, c_cz, c_trig})
    if (where_[c] < 0)
      throw dsp::InputError(file.string() + ":1: required column '" + column_name(c) + "' is missing" + also_unknown());
  n_psd_ = static_cast<int>(meta.psd.size());
  if (n_psd_ > dsp::kMaxPsd)
    throw dsp::InputError(file.string() + ": more than " + std::to_string(dsp::kMaxPsd) + " [[psd]] strips");
  for (int k = 0; k < dsp::kMaxPsd; ++k)
    for (int e = 0; e < 2; ++e) {
      const int c = c_psd0 + 2 * k + e;
      if (k < n_psd_ && where_[c] < 0)
        throw dsp::InputError(file.string() + ":1: column '" + column_name(c) + "' is missing (run.toml has " +
                              std::to_string(n_psd_) + " [[psd]])" + also_unknown());
      if (k >= n_psd_ && where_[c] >= 0)
        throw dsp::InputError(file.string() + ":1: column '" + column_name(c) + "' has no [[psd]] table in run.toml");
    }
  if (!unknown.empty()) throw dsp::InputError(file.string() + ":1: " + unknown_text);
  for (int a = 0; a < 3; ++a) channels.ref[a] = where_[c_rx + a] >= 0;
  channels.psd_count = n_psd_;
  fields_.resize(static_cast<std::size_t>(n_fields_));
}

SampleReader::~SampleReader() = default;

bool SampleReader::next(dsp::Frame& out) {
  std::string_view line;
  if (!src_->next(line)) {
    if (rows_ == 0) throw dsp::InputError(file_.string() + ": no samples after the header");
    return false;
  }
  const auto& acq = meta_.acquisition;
  split_fields(*src_, file_, n_fields_, line, fields_);
  const Row row{*src_, fields_, where_.data()};
  dsp::Frame f;
  read_time(row, acq.fs_hz, prev_index_, f);
  read_accel(row, std::ldexp(1.0, acq.adc_bits - 1), f);
  read_temperatures(row, f);
  read_positions(row, f);
  read_psd_counts(row, n_psd_, acq.adc_lsb_volt, static_cast<double>(acq.adc_offset_counts), f);
  read_trigger(row, f);
  // A sensor is there when any field of its triplex is (run-format.md, One sensor): one
  // empty column of it is a dead channel, not an absent sensor.
  for (int s = 0; s < 2; ++s)
    if ((f.flags & dsp::frame_flag::sensor_fields_missing(s)) != dsp::frame_flag::sensor_fields_missing(s))
      seen_[s] = true;
  ++rows_;
  out = f;
  return true;
}

void absent_sensors_are_not_missing(const bool present[2], dsp::Frame& f) {
  for (int s = 0; s < 2; ++s)
    if (!present[s]) {
      f.flags &= ~(dsp::frame_flag::sensor_missing(s) | dsp::frame_flag::sensor_fields_missing(s));
      if (!(f.flags & dsp::frame_flag::sensor_missing(1 - s))) f.flags &= ~dsp::frame_flag::accel_missing;
    }
}

fs::path samples_file(const fs::path& dir) {
  const fs::path plain = dir / "samples.csv", gz = dir / "samples.csv.gz";
  const bool has_plain = fs::exists(plain), has_gz = fs::exists(gz);
  if (has_plain && has_gz)
    throw dsp::InputError(dir.string() + ": both samples.csv and samples.csv.gz exist; keep one");
  if (!has_plain && !has_gz) throw dsp::InputError(dir.string() + ": no samples.csv or samples.csv.gz");
  return has_plain ? plain : gz;
}

namespace {

void read_samples(const fs::path& file, dsp::Run& run) {
  SampleReader reader(file, run.meta, run.channels);
  dsp::Frame f;
  while (reader.next(f)) run.frames.push_back(f);
  // A triplex empty in every row is absent (a single-sensor run), not missing: its empty
  // fields flag nothing, and the other sensor's samples stay good.
  for (int s = 0; s < 2; ++s) run.meta.sensor_present[s] = reader.sensor_seen(s);
  if (!run.meta.sensor_present[0] && !run.meta.sensor_present[1])
    throw dsp::InputError(file.string() + ": no accelerometer data (every table_* and head_* field is empty)");
  for (auto& fr : run.frames) absent_sensors_are_not_missing(run.meta.sensor_present, fr);
}

}  // namespace

dsp::RunMeta read_run_meta(const fs::path& run_toml) {
  if (!fs::exists(run_toml)) throw dsp::InputError(run_toml.string() + ": no such file");
  const toml::table root = StrictTable::parse_file(run_toml.string());
  StrictTable t(root, run_toml.string(), "");
  dsp::RunMeta m;
  m.format = t.string("format");
  if (m.format != "eical-run/1") t.fail("format", "expected \"eical-run/1\", got \"" + m.format + "\"");
  m.id = t.string("id");
  if (const toml::node* n = t.node("created")) {
    if (auto dt = n->value<toml::date_time>()) {
      std::ostringstream os;
      os << *dt;
      m.created = os.str();
    } else if (auto s = n->value<std::string>()) {
      m.created = *s;
    } else {
      t.fail("created", "expected an RFC 3339 date-time");
    }
  }
  m.acquisition = read_acquisition(t.table("acquisition"));
  if (auto s = t.optional_table("site")) m.site = read_site(*s);
  if (auto s = t.optional_table("machine")) m.machine = read_machine(*s);
  if (auto s = t.optional_table("envelope")) m.envelope = read_envelope(*s);
  StrictTable sensors = t.table("sensors");
  m.sensors[0] = read_sensor(sensors.table("table"));
  m.sensors[1] = read_sensor(sensors.table("head"));
  sensors.finish();
  for (auto& p : t.tables("psd")) m.psd.push_back(read_psd(p));
  m.program = read_program(t.table("program"));
  if (auto r = t.optional_table("reference")) {
    dsp::Reference ref;
    ref.kind = r->string("kind");
    ref.axes = r->strings("axes");
    r->finish();
    m.reference = ref;
  }
  if (auto s = t.optional_table("setpoint")) m.setpoint = read_setpoint_origin(*s);
  t.finish();
  return m;
}

dsp::Run read_run(const fs::path& dir) {
  if (!fs::is_directory(dir)) throw dsp::InputError(dir.string() + ": not a run directory");
  dsp::Run run;
  run.meta = read_run_meta(dir / "run.toml");
  read_samples(samples_file(dir), run);
  const fs::path truth = dir / "truth.toml";
  if (fs::exists(truth)) {
    (void)StrictTable::parse_file(truth.string());  // must at least be valid TOML
    std::ifstream is(truth, std::ios::binary);
    run.truth_toml = std::string(std::istreambuf_iterator<char>(is), std::istreambuf_iterator<char>());
  }
  return run;
}

}  // namespace eical::drivers
