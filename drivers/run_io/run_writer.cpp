#include "drivers/run_io/run_writer.hpp"

#include "drivers/run_io/sample_rows.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <random>
#include <stdexcept>
#include <string>

namespace eical::drivers {
namespace fs = std::filesystem;
namespace {

[[noreturn]] void sys_fail(const fs::path& p, const char* what, int err) {
  throw std::runtime_error(p.string() + ": " + what + ": " + std::strerror(err));
}

std::string toml_double(double v) {
  std::string s;
  append_double(s, v);
  if (s.find_first_of(".eEn") == std::string::npos) s += ".0";
  return s;
}

std::string toml_str(const std::string& s) {
  std::string o = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') o += '\\';
    if (c == '\n') {
      o += "\\n";
      continue;
    }
    o += c;
  }
  return o + "\"";
}

std::string vec(const double* v, int n) {
  std::string s = "[";
  for (int i = 0; i < n; ++i) s += (i ? ", " : "") + toml_double(v[i]);
  return s + "]";
}

std::string strs(const std::vector<std::string>& v) {
  std::string s = "[";
  for (std::size_t i = 0; i < v.size(); ++i) s += (i ? ", " : "") + toml_str(v[i]);
  return s + "]";
}

}  // namespace

std::string sensor_section_toml(const char* name, const dsp::SensorSpec& spec) {
  std::string o = std::string("\n[sensors.") + name + "]\nmodel = " + toml_str(spec.model) + "\nto_machine = [";
  for (int r = 0; r < 3; ++r) {
    const double row[3] = {spec.to_machine(r, 0), spec.to_machine(r, 1), spec.to_machine(r, 2)};
    o += (r ? ", " : "") + vec(row, 3);
  }
  o += "]\nk1_v_per_g = " + vec(spec.k1_v_per_g.data(), 3) + "\nk2_g_per_g2 = " + vec(spec.k2_g_per_g2.data(), 3) +
       "\nk3_g_per_g3 = " + vec(spec.k3_g_per_g3.data(), 3) + "\nbias_g = " + vec(spec.bias_g.data(), 3) +
       "\ntc_k1_ppm_per_c = " + toml_double(spec.tc_k1_ppm_per_c) +
       "\ntc_bias_ug_per_c = " + toml_double(spec.tc_bias_ug_per_c) + "\nf0_hz = " + toml_double(spec.f0_hz) +
       "\nzeta = " + toml_double(spec.zeta) + "\nnoise_ug_per_rthz = " + toml_double(spec.noise_ug_per_rthz) +
       "\nbias_walk_ug_per_rts = " + toml_double(spec.bias_walk_ug_per_rts) +
       "\ntemp_ref_c = " + toml_double(spec.temp_ref_c) + "\n";
  if (spec.zeta_per_g != 0.0)
    o += "zeta_per_g = " + toml_double(spec.zeta_per_g) + "\n";  // not a data-sheet key: only when found
  return o;
}

std::string toml_number(double v) { return toml_double(v); }

void write_text_atomic(const fs::path& file, const std::string& text) {
  const fs::path tmp = file.string() + ".tmp";
  std::error_code ec;
  {
    std::ofstream os(tmp, std::ios::binary | std::ios::trunc);
    if (!os) throw std::runtime_error(tmp.string() + ": cannot create");
    os << text;
    if (!os.flush()) {
      os.close();
      fs::remove(tmp, ec);  // no half file left beside the run
      throw std::runtime_error(tmp.string() + ": write failed (disk full?)");
    }
  }
  fs::rename(tmp, file, ec);
  if (ec) throw std::runtime_error(file.string() + ": " + ec.message());
}

namespace {

class FileOut {
 public:
  FileOut(const fs::path& p, bool gzip) : path_(p), gzip_(gzip) {
    fd_ = ::open(p.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (fd_ < 0) sys_fail(p, "cannot create", errno);
    if (gzip_) {
      const int dup = ::dup(fd_);
      gz_ = gzdopen(dup, "wb6");
      if (!gz_) sys_fail(p, "cannot start gzip", errno);
    }
    buf_.reserve(1 << 20);
  }
  ~FileOut() {
    if (gz_) gzclose(gz_);
    if (fd_ >= 0) ::close(fd_);
  }
  std::string& buffer() { return buf_; }
  void flush_if_full() {
    if (buf_.size() > (1 << 20) - 4096) flush();
  }
  void flush() {
    if (buf_.empty()) return;
    if (gzip_) {
      if (gzwrite(gz_, buf_.data(), static_cast<unsigned>(buf_.size())) != static_cast<int>(buf_.size())) {
        int code = 0;
        const char* msg = gzerror(gz_, &code);
        throw std::runtime_error(path_.string() + ": write failed: " + (code == Z_ERRNO ? std::strerror(errno) : msg));
      }
    } else {
      std::size_t done = 0;
      while (done < buf_.size()) {
        const ssize_t n = ::write(fd_, buf_.data() + done, buf_.size() - done);
        if (n < 0) {
          if (errno == EINTR) continue;
          sys_fail(path_, "write failed", errno);
        }
        done += static_cast<std::size_t>(n);
      }
    }
    buf_.clear();
  }
  void close_and_sync() {
    flush();
    if (gz_) {
      const int rc = gzclose(gz_);
      gz_ = nullptr;
      if (rc != Z_OK) sys_fail(path_, "gzip close failed", errno);
    }
    if (::fsync(fd_) != 0) sys_fail(path_, "fsync failed", errno);
    if (::close(fd_) != 0) sys_fail(path_, "close failed", errno);
    fd_ = -1;
  }

 private:
  fs::path path_;
  bool gzip_;
  int fd_ = -1;
  gzFile gz_ = nullptr;
  std::string buf_;
};

void write_samples(const dsp::Run& run, const fs::path& file, bool gzip) {
  FileOut out(file, gzip);
  std::string& b = out.buffer();
  b = samples_header(run.channels);
  for (const auto& f : run.frames) {
    append_sample_row(b, f, run.meta, run.channels);
    out.flush_if_full();
  }
  out.close_and_sync();
}

}  // namespace

void write_synced(const fs::path& file, const std::string& text) {
  FileOut f(file, false);
  f.buffer() = text;
  f.close_and_sync();
}

void sync_dir(const fs::path& dir) {
  const int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) sys_fail(dir, "cannot open directory to sync", errno);
  const int rc = ::fsync(fd);
  const int err = errno;
  ::close(fd);
  if (rc != 0) sys_fail(dir, "fsync of the directory failed", err);
}

std::string run_toml_text(const dsp::RunMeta& meta) {
  std::string o;
  o += "format = \"eical-run/1\"\nid = " + toml_str(meta.id) + "\n";
  if (!meta.created.empty()) o += "created = " + meta.created + "\n";
  const auto& a = meta.acquisition;
  o += "\n[acquisition]\nfs_hz = " + toml_double(a.fs_hz) + "\nadc_bits = " + std::to_string(a.adc_bits) +
       "\nadc_lsb_volt = " + toml_double(a.adc_lsb_volt) +
       "\nadc_offset_counts = " + std::to_string(a.adc_offset_counts) +
       "\ndaq_group_delay_samples = " + toml_double(a.daq_group_delay_samples) + "\n";
  if (a.daq_skew_head_samples != 0.0) o += "daq_skew_head_samples = " + toml_double(a.daq_skew_head_samples) + "\n";
  o += "\n[site]\nlatitude_deg = " + toml_double(meta.site.latitude_deg) +
       "\nheading_deg = " + toml_double(meta.site.heading_deg) + "\ng_mps2 = " + toml_double(meta.site.g_mps2) + "\n";
  o += "\n[machine]\nname = " + toml_str(meta.machine.name) + "\ntable_axes = " + strs(meta.machine.table_axes) +
       "\nhead_axes = " + strs(meta.machine.head_axes) + "\n";
  if (meta.envelope) {
    const dsp::WorkEnvelope& e = *meta.envelope;
    o += "\n[envelope]\ntravel_x_mm = " + vec(e.travel_mm[0], 2) + "\ntravel_y_mm = " + vec(e.travel_mm[1], 2) +
         "\ntravel_z_mm = " + vec(e.travel_mm[2], 2) + "\nmax_feed_mm_min = " + toml_double(e.max_feed_mm_min) +
         "\nmax_accel_mm_s2 = " + toml_double(e.max_accel_mm_s2) + "\n";
  }
  o += sensor_section_toml("table", meta.sensors[0]);
  o += sensor_section_toml("head", meta.sensors[1]);
  const auto& p = meta.program;
  o += "\n[program]\nkind = " + toml_str(dsp::program_kind_name(p.kind)) + "\nplane = " + toml_str(p.plane) +
       "\ncenter_mm = " + vec(p.center_mm, 2) + "\nradius_mm = " + toml_double(p.radius_mm) +
       "\nfeed_mm_min = " + toml_double(p.feed_mm_min) + "\ndirection = " + toml_str(p.direction) +
       "\nrepeats = " + std::to_string(p.repeats) + "\naxis = " + toml_str(p.axis) +
       "\ntargets_mm = " + vec(p.targets_mm.data(), static_cast<int>(p.targets_mm.size())) +
       "\nruns = " + std::to_string(p.runs) + "\ndwell_s = " + toml_double(p.dwell_s) +
       "\ncorner_mm = " + vec(p.corner_mm, 2) + "\nsize_mm = " + vec(p.size_mm, 2) + "\n";
  if (p.arc_deg < 360.0) o += "arc_deg = " + toml_double(p.arc_deg) + "\n";
  if (p.arc_start_deg) o += "arc_start_deg = " + toml_double(*p.arc_start_deg) + "\n";
  if (!p.gcode.empty()) o += "gcode = \"\"\"\n" + p.gcode + "\"\"\"\n";
  for (const auto& s : meta.psd) {
    o += "\n[[psd]]\nmeasures = " + toml_str(s.measures) + "\ncenter_mm = " + vec(s.center_mm, 2) +
         "\nlength_mm = " + toml_double(s.length_mm) + "\nwidth_mm = " + toml_double(s.width_mm) +
         "\nlockin_tau_s = " + toml_double(s.lockin_tau_s) + "\n";
  }
  if (meta.reference)
    o += "\n[reference]\nkind = " + toml_str(meta.reference->kind) + "\naxes = " + strs(meta.reference->axes) + "\n";
  if (meta.setpoint) {
    const auto& s = *meta.setpoint;
    o += "\n[setpoint]\nsource = " + toml_str(s.source) + "\n";
    if (s.program_number >= 0) o += "program_number = " + std::to_string(s.program_number) + "\n";
    if (s.source == "servo_stream")
      o += "servo_cycle_at_first_sample = " + toml_double(s.servo_cycle_at_first_sample) +
           "\nservo_rate_hz = " + toml_double(s.servo_rate_hz) + "\n";
    if (s.source == "program")
      o += "marks_offset_s = " + toml_double(s.marks_offset_s) + "\noffset_s = " + toml_double(s.offset_s) +
           "\nblocks = " + std::to_string(s.blocks) +
           "\nblock_offset_spread_s = " + toml_double(s.block_offset_spread_s) + "\n";
    o += "lag_s = " + toml_double(s.lag_s) + "\ncorrelation = " + toml_double(s.correlation) +
         "\nresidual_ratio = " + toml_double(s.residual_ratio) + "\n";
  }
  return o;
}

void write_run(const dsp::Run& run, const fs::path& dir_in, const WriteOptions& options) {
  const fs::path dir = dir_in.has_filename() ? dir_in : dir_in.parent_path();
  std::error_code ec;
  if (fs::exists(dir, ec) && !options.overwrite)
    throw std::runtime_error(dir.string() + ": a run already exists here (not overwritten)");
  const fs::path parent = dir.parent_path().empty() ? fs::path(".") : dir.parent_path();
  if (!fs::exists(parent, ec)) fs::create_directories(parent, ec);  // like mkdir -p; errors surface below
  if (!fs::is_directory(parent, ec))
    throw std::runtime_error(parent.string() + ": not a directory or cannot be created");
  std::random_device rd;
  const fs::path tmp = parent / ("." + dir.filename().string() + ".tmp-" + std::to_string(rd()));
  if (::mkdir(tmp.c_str(), 0755) != 0) sys_fail(tmp, "cannot create", errno);
  try {
    write_synced(tmp / "run.toml", run_toml_text(run.meta));
    write_samples(run, tmp / (options.gzip ? "samples.csv.gz" : "samples.csv"), options.gzip);
    if (run.truth_toml) write_synced(tmp / "truth.toml", *run.truth_toml);
    sync_dir(tmp);
    if (fs::exists(dir)) {
      // Replace atomically: old run aside, new in, old removed.
      const fs::path old = parent / ("." + dir.filename().string() + ".old-" + std::to_string(rd()));
      if (::rename(dir.c_str(), old.c_str()) != 0) sys_fail(dir, "cannot move the old run aside", errno);
      if (::rename(tmp.c_str(), dir.c_str()) != 0) {
        const int err = errno;
        (void)::rename(old.c_str(), dir.c_str());
        sys_fail(dir, "cannot rename the new run into place", err);
      }
      fs::remove_all(old, ec);
    } else if (::rename(tmp.c_str(), dir.c_str()) != 0) {
      sys_fail(dir, "cannot rename the new run into place", errno);
    }
    sync_dir(parent);
  } catch (...) {
    fs::remove_all(tmp, ec);
    throw;
  }
}

}  // namespace eical::drivers
