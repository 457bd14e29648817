#include "dsp/model/effect_selection.hpp"
#include "dsp/core/error.hpp"
#include "dsp/model/effects.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <iterator>
#include <numbers>
#include <random>
#include <string>

namespace eical::dsp::model {
namespace {

constexpr int kN = 20000;

// Red noise (AR(1), correlation time ~ 1/(1−phi) samples) as integration residuals are.
Eigen::VectorXd red_noise(std::uint64_t seed, double sigma, double phi) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> n(0.0, sigma * std::sqrt(1 - phi * phi));
  Eigen::VectorXd x(kN);
  double s = 0.0;
  for (int i = 0; i < kN; ++i) x(i) = s = phi * s + n(rng);
  return x;
}

std::vector<bool> every_other_block(int block) {
  std::vector<bool> h(kN);
  for (int i = 0; i < kN; ++i) h[static_cast<std::size_t>(i)] = (i / block) % 2 == 1;
  return h;
}

Candidate single(const std::string& name, const Eigen::VectorXd& col) {
  Candidate c;
  c.name = name;
  c.regressors = col;
  c.param_names = {"k"};
  return c;
}

TEST(EffectSelection, FindsTheTrueEffectFirstAndRejectsTheRest) {
  Eigen::VectorXd t = Eigen::VectorXd::LinSpaced(kN, 0.0, 8.0);
  const Eigen::VectorXd v = (2 * std::numbers::pi * 0.66 * t).array().cos();
  const Eigen::VectorXd a = -(2 * std::numbers::pi * 0.66 * t).array().sin();
  const Eigen::VectorXd va = v.array() * a.array().abs();
  const Eigen::VectorXd residual = 3.0 * va + red_noise(1, 0.3, 0.99);
  std::vector<Candidate> cands = {single("sensor.scale", a), single("sensor.damping_amplitude", va),
                                  single("site.coriolis", red_noise(2, 1.0, 0.999))};
  Candidate noise;
  noise.name = "other.noise_block";
  noise.regressors = Eigen::MatrixXd::Random(kN, 30);
  for (int k = 0; k < 30; ++k) noise.param_names.push_back("n" + std::to_string(k));
  cands.push_back(noise);
  const auto r = select_effects(residual, cands, every_other_block(500));
  ASSERT_FALSE(r.effects.empty());
  EXPECT_EQ(r.effects[0].name, "sensor.damping_amplitude");
  EXPECT_TRUE(r.effects[0].significant);
  EXPECT_NEAR(r.effects[0].params(0), 3.0, 0.1);
  int significant = 0;
  for (const auto& e : r.effects) significant += e.significant;
  EXPECT_EQ(significant, 1) << "only the injected effect may be accepted";
  EXPECT_EQ(r.effects.size(), cands.size());  // every candidate is reported
  EXPECT_LT(r.heldout_rms_final, 0.5 * r.heldout_rms_nominal);
  EXPECT_LT(r.n_eff, kN / 20.0);  // red noise: far fewer independent samples than samples
}

TEST(EffectSelection, SpuriousCorrelationOfRedNoiseIsNotSignificant) {
  // Two independent random walks correlate by chance; with n counted naively the BIC
  // would accept the regressor. The effective sample count and the held-out check must not.
  int accepted = 0;
  for (std::uint64_t seed = 10; seed < 20; ++seed) {
    const auto r =
        select_effects(red_noise(seed, 1.0, 0.999), {single("other.random_walk", red_noise(seed + 100, 1.0, 0.999))},
                       every_other_block(2000));
    accepted += r.effects[0].significant;
  }
  EXPECT_LE(accepted, 1);
}

TEST(EffectSelection, IntegratedAutocorrelationTime) {
  EXPECT_NEAR(integrated_autocorrelation_time(red_noise(5, 1.0, 0.0)), 1.0, 0.3);
  // AR(1): τ = (1 + φ)/(1 − φ) = 19 for φ = 0.9.
  EXPECT_NEAR(integrated_autocorrelation_time(red_noise(6, 1.0, 0.9)), 19.0, 4.0);
}

TEST(EffectSelection, BadInput) {
  Eigen::VectorXd r = Eigen::VectorXd::Zero(100);
  EXPECT_THROW((void)select_effects(r, {}, std::vector<bool>(99)), InputError);
  r(3) = std::nan("");
  EXPECT_THROW((void)select_effects(r, {}, std::vector<bool>(100, false)), InputError);
}

}  // namespace
}  // namespace eical::dsp::model

// The effect catalogue: one entry per run-format.md effect, in the order of the enum, every
// name unique and found again by effect_named.
TEST(EffectCatalogue, OneEntryPerEffectInEnumOrder) {
  const auto& cat = eical::dsp::model::effect_catalogue();
  for (std::size_t i = 0; i < cat.size(); ++i) {
    EXPECT_EQ(static_cast<std::size_t>(cat[i].id), i) << cat[i].name;
    ASSERT_TRUE(eical::dsp::model::effect_named(cat[i].name).has_value()) << cat[i].name;
    EXPECT_EQ(*eical::dsp::model::effect_named(cat[i].name), cat[i].id);
    EXPECT_GT(cat[i].bound, cat[i].tolerance) << cat[i].name;
    EXPECT_FALSE(cat[i].bound_reason.empty()) << cat[i].name;
  }
  EXPECT_FALSE(eical::dsp::model::effect_named("machine.nothing").has_value());
}

// docs/explain.md's table of physical bounds is the catalogue's: a bound changed in one
// place and not the other fails here.
TEST(EffectCatalogue, TheDocumentedBoundsTableIsTheCatalogue) {
  std::ifstream in(EICAL_SOURCE_DIR "/docs/explain.md");
  ASSERT_TRUE(in.good());
  const std::string readme((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  auto grouped = [](double v) {
    if (v >= 1e9) return std::string("none");
    std::string digits = std::to_string(static_cast<long long>(std::llround(v))), out;
    for (std::size_t i = 0; i < digits.size(); ++i)
      out += (i && (digits.size() - i) % 3 == 0 ? " " : "") + std::string(1, digits[i]);
    return out;
  };
  for (const auto& e : eical::dsp::model::effect_catalogue()) {
    const std::string row = "| `" + std::string(e.name) + "` | " + std::string(e.unit) + " | " + grouped(e.bound) +
                            " | " + grouped(e.bound_mems) + " | ";
    EXPECT_NE(readme.find(row), std::string::npos) << row;
  }
}
