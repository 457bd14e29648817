// eical identify RUN [-o CAL] [--json] [--compare-reference] [--delay-from-setpoint]:
// on-site identification of the sensors from an identification run (eical gen-nc
// identify), stored as the sensor calibration (eical-sensor-cal/1) that eical analyze
// --calibration and eicald's [calibration] file compensate with.
#include "drivers/config/sensor_calibration.hpp"
#include "drivers/run_io/run_reader.hpp"
#include "dsp/identify/axis_observations.hpp"
#include "dsp/identify/sensor_identification.hpp"
#include "tools/commands.hpp"

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <memory>
#include <string>

namespace eical::tools {
namespace {

const char* const kAxis[3] = {"x", "y", "z"};
const char* const kSensor[2] = {"table", "head"};

nlohmann::json estimate_json(const dsp::identify::Estimate& e) {
  if (!e.fitted) return nullptr;
  return {{"value", e.value}, {"sigma", e.sigma}};
}

nlohmann::json identification_json(const dsp::identify::Identification& id) {
  nlohmann::json j;
  j["method"] = id.method;
  for (int s = 0; s < 2; ++s) {
    const auto& se = id.sensor[s];
    nlohmann::json js;
    js["moved"] = se.moved;
    nlohmann::json e = nlohmann::json::object();
    for (int i = 0; i < 3; ++i)
      for (int k = 0; k < 3; ++k)
        if (se.error[i][k].fitted) e[std::string("E_") + kAxis[i] + kAxis[k]] = estimate_json(se.error[i][k]);
    js["acceleration_error"] = e;  // measured = (I + E) · true, machine axes
    js["damping_term_error_s"] = estimate_json(se.damping_s);
    js["zeta"] = id.sensors[s].zeta;
    js["rest_bias_g"] = {se.rest_bias_g.x(), se.rest_bias_g.y(), se.rest_bias_g.z()};
    j["sensors"][kSensor[s]] = js;
  }
  auto delay = [](const dsp::identify::DelayEstimate& d) -> nlohmann::json {
    if (!d.valid) return nullptr;
    return {{"samples", d.samples}, {"sigma", d.sigma}, {"against", d.against}, {"readings", d.fixes}};
  };
  j["delay"] = {{"psd_vs_setpoint", delay(id.delay_setpoint)},
                {"psd_vs_reference", delay(id.delay_reference)},
                {"daq_group_delay_samples", id.daq_group_delay_samples},
                {"identified", id.delay_identified}};
  for (int i = 0; i < 3; ++i) {
    j["machine"]["backlash_um"][kAxis[i]] = estimate_json(id.backlash_um[i]);
  }
  j["psd_offset_um"] = nlohmann::json::array();
  for (const auto& o : id.psd_offset_um) j["psd_offset_um"].push_back(estimate_json(o));
  j["psd_nonlinearity"] = nlohmann::json::array();
  for (const auto& n : id.psd_nonlinearity) j["psd_nonlinearity"].push_back(estimate_json(n));
  j["position_nis"] = {{"x", id.position_nis[0]}, {"y", id.position_nis[1]}, {"z", id.position_nis[2]}};
  j["agreement"] = {{"psd_rms_before_um", id.psd_rms_before_um},
                    {"psd_rms_after_um", id.psd_rms_after_um},
                    {"rest_rms_before_um", id.rest_rms_before_um},
                    {"rest_rms_after_um", id.rest_rms_after_um}};
  j["observations"] = {{"psd", id.psd_observations}, {"rest", id.rest_observations}, {"standstills", id.standstills}};
  j["iterations"] = id.iterations;
  j["strip_crossings"] = id.strip_crossings;
  j["crossing_speeds_mm_s"] = id.crossing_speeds_mm_s;
  nlohmann::json sig = nlohmann::json::object();
  for (int p = 0; p < dsp::kModelParameters; ++p) sig[dsp::parameter_name(p)] = id.covariance.sigma(p);
  j["standard_uncertainty"] = sig;  // σ of every model parameter (the data sheet's where not identified)
  j["notes"] = id.notes;
  return j;
}

std::string summary(const dsp::identify::Identification& id) {
  std::string o;
  char b[256];
  for (int s = 0; s < 2; ++s) {
    const auto& se = id.sensor[s];
    if (!se.moved) continue;
    std::snprintf(b, sizeof b, "%s sensor: acceleration error (measured = (I+E)·true), ppm ± σ\n", kSensor[s]);
    o += b;
    for (int i = 0; i < 3; ++i) {
      o += "   ";
      for (int k = 0; k < 3; ++k) {
        const auto& e = se.error[i][k];
        if (e.fitted)
          std::snprintf(b, sizeof b, "  E_%s%s %+9.1f ± %5.1f", kAxis[i], kAxis[k], e.value * 1e6, e.sigma * 1e6);
        else
          std::snprintf(b, sizeof b, "  E_%s%s %17s", kAxis[i], kAxis[k], "—");
        o += b;
      }
      o += "\n";
    }
    if (se.damping_s.fitted)
      std::snprintf(b, sizeof b, "   2ζ/ω0: data sheet − identified = %+.2f ± %.2f µs → ζ = %.4f at f0 = %.0f Hz\n",
                    se.damping_s.value * 1e6, se.damping_s.sigma * 1e6, id.sensors[s].zeta, id.sensors[s].f0_hz);
    else
      std::snprintf(b, sizeof b, "   2ζ/ω0: not identified, data sheet kept\n");
    o += b;
  }
  if (id.delay_setpoint.valid) {
    std::snprintf(b, sizeof b, "PSD behind the set-point: %.3f ± %.3f samples (DAQ delay + servo lag)\n",
                  id.delay_setpoint.samples, id.delay_setpoint.sigma);
    o += b;
  }
  if (id.delay_reference.valid) {
    std::snprintf(b, sizeof b, "PSD behind the reference: %.3f ± %.3f samples (DAQ delay)\n",
                  id.delay_reference.samples, id.delay_reference.sigma);
    o += b;
  }
  std::snprintf(b, sizeof b, "DAQ delay used: %.3f samples (%s)\n", id.daq_group_delay_samples,
                id.delay_identified ? "identified" : "data sheet");
  o += b;
  std::snprintf(b, sizeof b,
                "agreement with the PSD readings (not used by the pipeline): %.2f → %.2f µm RMS; set-point at "
                "standstills: %.2f → %.2f µm RMS\n",
                id.psd_rms_before_um, id.psd_rms_after_um, id.rest_rms_before_um, id.rest_rms_after_um);
  o += b;
  for (std::size_t s = 0; s < id.psd_nonlinearity.size(); ++s) {
    const auto& nl = id.psd_nonlinearity[s];
    if (!nl.fitted) continue;
    // Where the run did not cross the strip along its length the prior is all there is.
    if (nl.sigma >= 0.9 * dsp::identify::prior_strip_nonlinearity())
      std::snprintf(b, sizeof b, "PSD strip %zu: nonlinearity not resolved by the run (the data sheet's ± %.0e)\n",
                    s + 1, dsp::DatasheetTolerance{}.psd_nonlinearity);
    else
      std::snprintf(b, sizeof b, "PSD strip %zu: nonlinearity %+.1e ± %.1e (of u (1 + nl (2u/L)²))\n", s + 1, nl.value,
                    nl.sigma);
    o += b;
  }
  std::snprintf(b, sizeof b,
                "normalised innovations² of the strips and standstills (1 where the model holds): x %.2f, y %.2f, "
                "z %.2f\n",
                id.position_nis[0], id.position_nis[1], id.position_nis[2]);
  o += b;
  for (const auto& n : id.notes) o += "note: " + n + "\n";
  return o;
}

}  // namespace

void register_identify(CLI::App& app) {
  struct Opt {
    std::string run, out;
    bool json = false, compare_reference = false, delay_from_setpoint = false;
    double rest_sigma_um = 0.5;
  };
  auto o = std::make_shared<Opt>();
  auto* cmd = app.add_subcommand(
      "identify",
      "Identify the sensors on site from an identification run (PSD strips + set-point); write the sensor calibration");
  cmd->add_option("run", o->run, "identification run (eical gen-nc identify)")->required();
  cmd->add_option("-o,--out", o->out, "write the calibration here (eical-sensor-cal/1)");
  cmd->add_flag("--json", o->json, "print the eical-identify/1 document");
  cmd->add_flag("--compare-reference", o->compare_reference,
                "also identify against the run's reference instrument and compare");
  cmd->add_flag("--delay-from-setpoint", o->delay_from_setpoint,
                "store the PSD-vs-set-point delay (includes the servo lag) as the DAQ delay");
  cmd->add_option("--rest-sigma", o->rest_sigma_um,
                  "the machine's position at a standstill against its set-point, µm (σ)")
      ->default_val(0.5)
      ->check(CLI::PositiveNumber);
  cmd->callback([o] {
    const dsp::Run run = drivers::read_run(o->run);
    dsp::identify::IdentifyOptions opt;
    opt.rest_sigma_um = o->rest_sigma_um;
    opt.delay_from_setpoint = o->delay_from_setpoint;
    const dsp::identify::Identification id = dsp::identify::identify_sensors(run, opt);
    // A calibration less certain than the data sheet would make every figure worse.
    const auto worse = dsp::identify::less_certain_than_datasheet(
        id, dsp::datasheet_covariance(run.meta.sensors, run.meta.acquisition.fs_hz));
    if (!worse.empty()) {
      std::string list;
      for (std::size_t i = 0; i < worse.size() && i < 4; ++i) list += (i ? "; " : "") + worse[i];
      if (worse.size() > 4) list += "; and " + std::to_string(worse.size() - 4) + " more";
      throw std::runtime_error("identify: run '" + run.meta.id + "' leaves " + list +
                               " less certain than the data sheet: no calibration written (run the identification "
                               "program, eical gen-nc identify)");
    }
    nlohmann::json doc = {{"format", "eical-identify/1"}, {"run_id", run.meta.id}};
    doc["identification"] = identification_json(id);
    std::string text = summary(id);
    if (o->compare_reference) {
      dsp::identify::IdentifyOptions ro = opt;
      ro.against_reference = true;
      const dsp::identify::Identification ref = dsp::identify::identify_sensors(run, ro);
      doc["against_reference"] = identification_json(ref);
      nlohmann::json diff = nlohmann::json::object();
      text += "against the reference instrument (difference PSD − reference, in σ of the difference):\n";
      for (int s = 0; s < 2; ++s)
        for (int i = 0; i < 3; ++i)
          for (int k = 0; k < 3; ++k) {
            const auto& a = id.sensor[s].error[i][k];
            const auto& b = ref.sensor[s].error[i][k];
            if (!a.fitted || !b.fitted) continue;
            const double d = a.value - b.value, sg = std::hypot(a.sigma, b.sigma);
            diff[std::string(kSensor[s]) + ".E_" + kAxis[i] + kAxis[k]] = {{"difference", d}, {"sigma", sg}};
            char line[160];
            std::snprintf(line, sizeof line, "  %s E_%s%s: %+.1f ppm (%.1f σ)\n", kSensor[s], kAxis[i], kAxis[k],
                          d * 1e6, sg > 0 ? d / sg : 0.0);
            text += line;
          }
      doc["difference_psd_minus_reference"] = diff;
    }
    if (!o->out.empty()) {
      drivers::write_sensor_calibration(drivers::calibration_from(id, run.meta.id), o->out);
      text += "wrote " + o->out + "\n";
    }
    if (o->json)
      std::printf("%s\n", doc.dump(2).c_str());
    else
      std::fputs(text.c_str(), stdout);
  });
}

}  // namespace eical::tools
