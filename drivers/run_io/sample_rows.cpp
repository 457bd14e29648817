#include "drivers/run_io/sample_rows.hpp"

#include "dsp/core/frame_fields.hpp"

#include <charconv>
#include <cmath>

namespace eical::drivers {

void append_double(std::string& out, double v) {
  char buf[64];
  const double a = std::abs(v);
  const auto fmt = (a == 0.0 || (a >= 1e-9 && a < 1e15)) ? std::chars_format::fixed : std::chars_format::scientific;
  const auto r = std::to_chars(buf, buf + sizeof buf, v, fmt);
  out.append(buf, r.ptr);
}

std::string samples_header(const dsp::ChannelPresence& channels) {
  std::string b = "t,table_ax,table_ay,table_az,head_ax,head_ay,head_az,table_temp,head_temp";
  for (int k = 0; k < channels.psd_count; ++k) b += ",psd" + std::to_string(k) + "_i1,psd" + std::to_string(k) + "_i2";
  b += ",cmd_x,cmd_y,cmd_z";
  const char* ref_names[3] = {",ref_x", ",ref_y", ",ref_z"};
  for (int a = 0; a < 3; ++a)
    if (channels.ref[a]) b += ref_names[a];
  b += ",trigger\n";
  return b;
}

void append_sample_row(std::string& out, const dsp::Frame& f, const dsp::RunMeta& meta,
                       const dsp::ChannelPresence& channels) {
  const double fs = meta.acquisition.fs_hz;
  const double lsb = meta.acquisition.adc_lsb_volt;
  const auto offset = meta.acquisition.adc_offset_counts;
  char num[32];
  auto put_int = [&](std::int64_t v) {
    const auto r = std::to_chars(num, num + sizeof num, v);
    out.append(num, r.ptr);
  };
  append_double(out, static_cast<double>(f.sample_index) / fs);
  for (int c = 0; c < 6; ++c) {
    out += ',';
    const int sensor = c < 3 ? 0 : 1;
    // An absent triplex is written empty; a missing field of a present one too: the field
    // named, or every field of a sensor (or frame) whose flag names none.
    const bool named = (f.flags & dsp::frame_flag::sensor_fields_missing(sensor)) != 0;
    const bool missing = !meta.sensor_present[sensor] || (f.flags & dsp::frame_flag::accel_field_missing(c)) ||
                         (!named && (f.flags & dsp::frame_flag::sensor_missing(sensor))) ||
                         ((f.flags & dsp::frame_flag::accel_missing) &&
                          !(f.flags & (dsp::frame_flag::table_missing | dsp::frame_flag::head_missing)));
    if (!missing) put_int(f.accel_counts[c]);
  }
  for (int s = 0; s < 2; ++s) {
    out += ',';
    if (!(f.flags & dsp::frame_flag::temp_missing)) append_double(out, static_cast<double>(f.temp_c[s]));
  }
  for (int c = 0; c < 2 * channels.psd_count; ++c) {
    out += ',';
    if (!dsp::frame_flag::psd_electrode_empty(f, c))
      append_double(out, static_cast<double>(f.psd_counts[c] - offset) * lsb);
  }
  for (int a = 0; a < 3; ++a) {
    out += ',';
    if (!(f.flags & dsp::frame_flag::cmd_missing)) append_double(out, f.cmd_mm[a]);
  }
  for (int a = 0; a < 3; ++a) {
    if (!channels.ref[a]) continue;
    out += ',';
    if (std::isfinite(f.ref_mm[a])) append_double(out, f.ref_mm[a]);
  }
  out += ',';
  put_int(f.trigger);
  out += '\n';
}

}  // namespace eical::drivers
