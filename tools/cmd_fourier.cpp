// eical fourier: Fourier calibration function of a rotary axis from interleaved series
// (seed 001) with per-term significance and the GUM expanded uncertainty.
#include "dsp/comp/fourier.hpp"
#include "tools/commands.hpp"
#include "tools/io/csv_inputs.hpp"

#include <nlohmann/json.hpp>

#include <cstdio>
#include <memory>

namespace eical::tools {

void register_fourier(CLI::App& app) {
  struct Opt {
    std::string series, sweep;
    double alpha = 0.05, bound = 0.0;
    int max_f = 0;
    bool json = false;
  };
  auto o = std::make_shared<Opt>();
  auto* cmd = app.add_subcommand("fourier", "Fourier calibration function of a rotary axis (interleaved series)");
  cmd->add_option("--series", o->series, "CSV: angle_deg,deviation_arcsec,series")->required();
  cmd->add_option("--sweep", o->sweep, "name of the series that sweeps one interval continuously (recovers f = k*n)");
  cmd->add_option("--alpha", o->alpha, "significance level per term")->default_val(0.05)->check(CLI::Range(1e-6, 0.5));
  cmd->add_option("--positioning-bound-arcsec", o->bound, "positioning deviation bound +-a of the axis (GUM type B)")
      ->default_val(0.0);
  cmd->add_option("--max-frequency", o->max_f, "highest candidate frequency per revolution (0 = Nyquist)")
      ->default_val(0);
  cmd->add_flag("--json", o->json, "print JSON");
  cmd->callback([o] {
    const auto series = read_angle_series_csv(o->series);
    dsp::comp::FourierOptions opt;
    opt.alpha = o->alpha;
    opt.positioning_bound_arcsec = o->bound;
    opt.sweep_series = o->sweep;
    opt.max_frequency = o->max_f;
    const auto r = dsp::comp::fourier_calibration(series, opt);
    nlohmann::json terms = nlohmann::json::array();
    for (const auto& term : r.terms)
      terms.push_back({{"frequency_per_rev", term.frequency},
                       {"amplitude_arcsec", term.amplitude_arcsec},
                       {"phase_deg", term.phase_deg},
                       {"u_amplitude_arcsec", term.u_amplitude_arcsec},
                       {"F", term.test_statistic},
                       {"significant", term.significant},
                       {"from_sweep", term.from_sweep}});
    const nlohmann::json j = {{"model", "F(x) = sum A_l sin(f_l x + phi_l)"},
                              {"points_per_series", r.points_per_series},
                              {"series", r.series},
                              {"series_offset_arcsec", r.series_offset_arcsec},
                              {"lost_frequencies", r.lost_frequencies},
                              {"terms", terms},
                              {"residual_rms_arcsec", r.residual_rms_arcsec},
                              {"u_x_arcsec", r.u_x_arcsec},
                              {"u_p_arcsec", r.u_p_arcsec},
                              {"U_arcsec", r.expanded_U_arcsec},
                              {"coverage_factor", 2},
                              {"alpha", o->alpha}};
    if (o->json) {
      std::printf("%s\n", j.dump(2).c_str());
      return;
    }
    std::printf("n = %d positions per series, %d series; lost by centring: ", r.points_per_series, r.series);
    for (int f : r.lost_frequencies) std::printf("%d ", f);
    std::printf("\n  f/rev   A (arcsec)   phase (deg)   u(A)    significant\n");
    for (const auto& term : r.terms)
      std::printf("  %5d   %10.3f   %11.2f   %6.3f  %s%s\n", term.frequency, term.amplitude_arcsec, term.phase_deg,
                  term.u_amplitude_arcsec, term.significant ? "yes" : "no", term.from_sweep ? " (sweep)" : "");
    std::printf("residual RMS %.3f arcsec; U = 2*sqrt(u_x^2 + u_p^2) = %.3f arcsec (u_x %.3f, u_p %.3f)\n",
                r.residual_rms_arcsec, r.expanded_U_arcsec, r.u_x_arcsec, r.u_p_arcsec);
  });
}

}  // namespace eical::tools
