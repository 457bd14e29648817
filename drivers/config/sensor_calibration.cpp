#include "drivers/config/sensor_calibration.hpp"

#include "drivers/config/meta_sections.hpp"
#include "drivers/config/strict_toml.hpp"
#include "drivers/run_io/run_writer.hpp"
#include "dsp/core/error.hpp"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <stdexcept>

namespace eical::drivers {
namespace {

constexpr const char* kFormat = "eical-sensor-cal/1";
constexpr const char* kSensorNames[2] = {"table", "head"};

Eigen::Matrix3d read_matrix(StrictTable& t, const char* key) {
  const auto rows = t.matrix(key, 3, 3);
  Eigen::Matrix3d m;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) m(r, c) = rows[static_cast<std::size_t>(r)][static_cast<std::size_t>(c)];
  if (!m.allFinite()) t.fail(key, "not finite");
  return m;
}

std::string matrix_toml(const Eigen::Matrix3d& m) {
  std::string s = "[";
  for (int r = 0; r < 3; ++r) {
    s += r ? ", [" : "[";
    for (int c = 0; c < 3; ++c) s += (c ? ", " : "") + toml_number(m(r, c));
    s += "]";
  }
  return s + "]";
}

// [covariance]: named parameters, a symmetric positive semi-definite matrix over them.
dsp::SensorModelCovariance read_covariance(StrictTable& t, const dsp::RunMeta& datasheet) {
  namespace u = dsp;
  u::SensorModelCovariance c = u::datasheet_covariance(datasheet.sensors, datasheet.acquisition.fs_hz);
  const std::vector<std::string> names = t.strings("parameters");
  std::vector<int> index;
  for (const auto& n : names) {
    const int p = u::parameter_index(n);
    if (p < 0)
      t.fail("parameters",
             "unknown parameter '" + n + "' (table.E_xx … head.E_zz, table.c1_s, head.c1_s, daq.delay_s)");
    if (std::find(index.begin(), index.end(), p) != index.end()) t.fail("parameters", "'" + n + "' is listed twice");
    index.push_back(p);
  }
  const auto rows = t.matrix("matrix", names.size(), names.size());
  const auto m = static_cast<Eigen::Index>(names.size());
  Eigen::MatrixXd cov(m, m);
  for (Eigen::Index r = 0; r < m; ++r)
    for (Eigen::Index k = 0; k < m; ++k) cov(r, k) = rows[static_cast<std::size_t>(r)][static_cast<std::size_t>(k)];
  if (!cov.allFinite()) t.fail("matrix", "not finite");
  const double scale = std::max(1e-300, cov.diagonal().cwiseAbs().maxCoeff());
  if ((cov - cov.transpose()).cwiseAbs().maxCoeff() > 1e-9 * scale) t.fail("matrix", "not symmetric");
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(cov);
  if (eig.eigenvalues().minCoeff() < -1e-9 * scale)
    t.fail("matrix", "not positive semi-definite (a variance below zero)");
  for (Eigen::Index r = 0; r < m; ++r)
    for (Eigen::Index k = 0; k < m; ++k)
      c.covariance(index[static_cast<std::size_t>(r)], index[static_cast<std::size_t>(k)]) = cov(r, k);
  if (t.has("psd_offset_sigma_um")) {
    c.psd_offset_sigma_um = t.number("psd_offset_sigma_um");
    if (!(c.psd_offset_sigma_um >= 0.0 && c.psd_offset_sigma_um < 1000.0))
      t.fail("psd_offset_sigma_um", "must be within [0, 1000) µm");
  }
  return c;
}

}  // namespace

SensorCalibration read_sensor_calibration(const std::filesystem::path& file, const dsp::RunMeta& datasheet) {
  const toml::table doc = StrictTable::parse_file(file.string());
  StrictTable root(doc, file.string(), "");
  const std::string format = root.string("format");
  if (format != kFormat) root.fail("format", "expected \"" + std::string(kFormat) + "\", got \"" + format + "\"");
  SensorCalibration cal;
  cal.method = root.choice("method", {"psd", "ref", "explain"}, "psd");
  cal.run_id = root.string("run", "");
  if (auto acq = root.optional_table("acquisition")) {
    if (acq->has("daq_group_delay_samples")) {
      const double d = acq->number("daq_group_delay_samples");
      if (!(d >= 0.0 && d < 10000.0)) acq->fail("daq_group_delay_samples", "must be within [0, 10000) samples");
      cal.daq_group_delay_samples = d;
    }
    if (acq->has("daq_skew_head_samples")) {
      const double d = acq->number("daq_skew_head_samples");
      if (!(std::abs(d) < 1000.0)) acq->fail("daq_skew_head_samples", "must be within (-1000, 1000) samples");
      cal.daq_skew_head_samples = d;
    }
    acq->finish();
  }
  for (int s = 0; s < 2; ++s) cal.sensors[s] = datasheet.sensors[s];
  if (auto sensors = root.optional_table("sensors")) {
    for (int s = 0; s < 2; ++s) {
      auto t = sensors->optional_table(kSensorNames[s]);
      if (!t) continue;
      if (t->has("cross_g_per_g")) cal.static_cal[s].cross_g_per_g = read_matrix(*t, "cross_g_per_g");
      // read_sensor checks the rest strictly (its copy knows cross_g_per_g was read).
      cal.sensors[s] = read_sensor(*t, datasheet.sensors[s]);
    }
    sensors->finish();
  }
  if (auto cov = root.optional_table("covariance")) {
    cal.covariance = read_covariance(*cov, datasheet);
    cal.covariance->source = cal.method;
    cov->finish();
  }
  root.finish();
  return cal;
}

void write_sensor_calibration(const SensorCalibration& cal, const std::filesystem::path& file) {
  std::string o = "# Sensor calibration: eical-sensor-cal/1 (identified on site; see README).\n";
  // Appended piecewise: GCC 12 warns falsely (-Warray-bounds) on the long temporary chain.
  o += "format = \"";
  o += kFormat;
  o += "\"\nmethod = \"";
  o += cal.method;
  o += "\"\nrun = \"";
  o += cal.run_id;
  o += "\"\n";
  if (cal.daq_group_delay_samples || cal.daq_skew_head_samples) o += "\n[acquisition]\n";
  if (cal.daq_group_delay_samples) o += "daq_group_delay_samples = " + toml_number(*cal.daq_group_delay_samples) + "\n";
  if (cal.daq_skew_head_samples) o += "daq_skew_head_samples = " + toml_number(*cal.daq_skew_head_samples) + "\n";
  for (int s = 0; s < 2; ++s) {
    o += sensor_section_toml(kSensorNames[s], cal.sensors[s]);
    o += "cross_g_per_g = " + matrix_toml(cal.static_cal[s].cross_g_per_g) + "\n";
  }
  if (cal.covariance) {
    // The parameters with a variance (every other keeps the data sheet's, by definition).
    namespace u = dsp;
    std::vector<int> used;
    for (int p = 0; p < u::kModelParameters; ++p)
      if (cal.covariance->covariance(p, p) > 0.0) used.push_back(p);
    o += "\n[covariance]  # of the parameters below (sensor_model_covariance.hpp): E dimensionless, c1 and delay in "
         "s\nparameters = [";
    for (std::size_t i = 0; i < used.size(); ++i) o += (i ? ", \"" : "\"") + u::parameter_name(used[i]) + "\"";
    o += "]\nmatrix = [";
    for (std::size_t r = 0; r < used.size(); ++r) {
      o += r ? ",\n  [" : "\n  [";
      for (std::size_t k = 0; k < used.size(); ++k)
        o += (k ? ", " : "") + toml_number(cal.covariance->covariance(used[r], used[k]));
      o += "]";
    }
    o += "]\npsd_offset_sigma_um = " + toml_number(cal.covariance->psd_offset_sigma_um) + "\n";
  }
  write_text_atomic(file, o);
}

void apply_calibration(const SensorCalibration& cal, dsp::RunMeta& meta) {
  for (int s = 0; s < 2; ++s) meta.sensors[s] = cal.sensors[s];
  if (cal.daq_group_delay_samples) meta.acquisition.daq_group_delay_samples = *cal.daq_group_delay_samples;
  if (cal.daq_skew_head_samples) meta.acquisition.daq_skew_head_samples = *cal.daq_skew_head_samples;
}

void apply_calibration(const SensorCalibration& cal, dsp::PipelineConfig& config) {
  for (int s = 0; s < 2; ++s) {
    config.sensors[s] = cal.sensors[s];
    config.calibration[s].cross_g_per_g = cal.static_cal[s].cross_g_per_g;
  }
  if (cal.daq_group_delay_samples) config.acquisition.daq_group_delay_samples = *cal.daq_group_delay_samples;
  if (cal.daq_skew_head_samples) config.acquisition.daq_skew_head_samples = *cal.daq_skew_head_samples;
}

void apply_calibration(const SensorCalibration& cal, dsp::RunMeta& meta, dsp::AnalysisOptions& options) {
  apply_calibration(cal, meta);
  for (int s = 0; s < 2; ++s) options.calibration[s].cross_g_per_g = cal.static_cal[s].cross_g_per_g;
  options.sensor_model = cal.method;
  // Without its own covariance a calibration is as uncertain as the data sheet.
  options.model_covariance =
      cal.covariance ? *cal.covariance : dsp::datasheet_covariance(meta.sensors, meta.acquisition.fs_hz);
  if (!cal.covariance)
    options.model_covariance->source = cal.method + " (no covariance in the file: the data sheet's tolerance)";
}

SensorCalibration calibration_from(const dsp::identify::Identification& id, const std::string& run_id) {
  SensorCalibration cal;
  cal.method = id.method;
  cal.run_id = run_id;
  if (id.delay_identified) cal.daq_group_delay_samples = id.daq_group_delay_samples;
  for (int s = 0; s < 2; ++s) {
    cal.sensors[s] = id.sensors[s];
    cal.static_cal[s] = id.calibration[s];
  }
  cal.covariance = id.covariance;
  return cal;
}

}  // namespace eical::drivers
