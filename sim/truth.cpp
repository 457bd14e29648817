#include "sim/truth.hpp"

#include <cmath>
#include <cstdio>
#include <vector>

namespace eical::sim {
namespace {

std::string num(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.10g", v);
  std::string s = buf;
  // TOML floats need a decimal point or exponent.
  if (s.find_first_of(".eEn") == std::string::npos) s += ".0";
  return s;
}

std::string vec3(const Eigen::Vector3d& v) { return "[" + num(v[0]) + ", " + num(v[1]) + ", " + num(v[2]) + "]"; }

std::string mat3(const Eigen::Matrix3d& m) {
  std::string s = "[";
  for (int r = 0; r < 3; ++r) s += (r ? ", " : "") + vec3(m.row(r).transpose());
  return s + "]";
}

bool differs(double a, double b) { return std::abs(a - b) > 1e-12 * std::max(1.0, std::abs(b)); }
bool differs(const Eigen::Vector3d& a, const Eigen::Vector3d& b) { return (a - b).norm() > 1e-12; }

}  // namespace

std::string truth_toml(const Scenario& sc, const nc::Trajectory& tr) {
  std::vector<std::string> present;
  for (int s = 0; s < 2; ++s) {
    const auto& t = sc.truth[s].spec;
    const auto& n = sc.meta.sensors[s];
    auto add = [&](const char* e) {
      for (const auto& p : present)
        if (p == e) return;
      present.emplace_back(e);
    };
    if (differs(t.k1_v_per_g, n.k1_v_per_g)) add("sensor.scale");
    if (differs(t.k2_g_per_g2, n.k2_g_per_g2) || differs(t.k3_g_per_g3, n.k3_g_per_g3)) add("sensor.nonlinearity");
    if (differs(t.f0_hz, n.f0_hz) || differs(t.zeta, n.zeta)) add("sensor.dynamics");
    if ((t.to_machine - n.to_machine).norm() > 1e-12) add("sensor.misalignment");
  }
  if (differs(sc.daq_delay_samples_true, sc.meta.acquisition.daq_group_delay_samples)) present.emplace_back("daq.group_delay");

  std::string o;
  o += "# truth.toml -- synthetic run, true parameters (eical sim v1).\n";
  o += "# Noise densities are two-sided (sample std = n sqrt(fs)). Machine: ideal (relative\n";
  o += "# position = NC set-point); no PSD, no vibration, no temperature drift in v1.\n";
  o += "generator = \"eical-sim 1\"\n";
  o += "scenario = \"" + sc.name + "\"\n";
  o += "seed = " + std::to_string(sc.seed) + "\n";
  o += "description = \"" + sc.description + "\"\n\n[effects]\npresent = [";
  for (std::size_t k = 0; k < present.size(); ++k) o += (k ? ", \"" : "\"") + present[k] + "\"";
  o += "]\nbackground = []\n";
  const char* names[2] = {"table", "head"};
  for (int s = 0; s < 2; ++s) {
    const auto& t = sc.truth[s].spec;
    o += std::string("\n[sensors.") + names[s] + "]\n";
    o += "model = \"" + t.model + "\"\n";
    o += "to_machine = " + mat3(t.to_machine) + "\n";
    o += "k1_v_per_g = " + vec3(t.k1_v_per_g) + "\n";
    o += "k2_g_per_g2 = " + vec3(t.k2_g_per_g2) + "\n";
    o += "k3_g_per_g3 = " + vec3(t.k3_g_per_g3) + "\n";
    o += "bias_g = " + vec3(t.bias_g) + "\n";
    o += "tc_k1_ppm_per_c = " + num(t.tc_k1_ppm_per_c) + "\n";
    o += "tc_bias_ug_per_c = " + num(t.tc_bias_ug_per_c) + "\n";
    o += "f0_hz = " + num(t.f0_hz) + "\nzeta = " + num(t.zeta) + "\n";
    o += "noise_ug_per_rthz = " + num(sc.noise ? t.noise_ug_per_rthz : 0.0) + "\n";
    o += "temp_ref_c = " + num(t.temp_ref_c) + "\n";
    o += std::string("\n[sensors.") + names[s] + ".temperature]\nstart_c = " + num(sc.truth[s].temp_c) +
         "\nend_c = " + num(sc.truth[s].temp_c) + "\n";
  }
  o += "\n[daq]\ngroup_delay_samples = " + num(sc.daq_delay_samples_true) + "\nskew_samples = 0.0\n";
  o += "\n[site]\nlatitude_deg = " + num(sc.meta.site.latitude_deg) + "\nheading_deg = " + num(sc.meta.site.heading_deg) +
       "\ng_mps2 = " + num(sc.meta.site.g_mps2) + "\n";
  o += "\n[nc]\na_max_mps2 = " + num(sc.limits.a_max_mm_s2 / 1000.0) + "\njerk_mps3 = " + num(sc.limits.j_max_mm_s3 / 1000.0) +
       "\nmoves_s = [";
  for (std::size_t k = 0; k < tr.moves().size(); ++k) {
    const auto& m = tr.moves()[k];
    o += (k ? ", [" : "[") + num(m.t0_s) + ", " + num(m.t0_s + m.profile.duration_s()) + "]";
  }
  o += "]\ntriggers = [";
  for (std::size_t k = 0; k < tr.triggers().size(); ++k)
    o += (k ? ", [" : "[") + num(tr.triggers()[k].t_s) + ", " + std::to_string(tr.triggers()[k].code) + "]";
  o += "]\n\n[machine_errors]\n# none: ideal machine\n";
  return o;
}

}  // namespace eical::sim
