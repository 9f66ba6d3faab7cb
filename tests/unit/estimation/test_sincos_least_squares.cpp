// Signal-domain least squares (reference fit and conic fit) on simulated data.
//
// Tolerances come from the Cramer-Rao bound (cramer_rao.h) with the data's noise:
// an efficient, unbiased estimator errs by more than 5 CRLB with probability
// 6e-7 per parameter, so a 5x CRLB check fails only when the estimator is biased
// or inefficient. The simulator's i16 samples carry sigma_eff = sqrt(sigma^2 + 1/12).
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "daemon/core/estimation/cramer_rao.h"
#include "daemon/core/estimation/sincos_least_squares.h"
#include "estimator_test_support.h"

namespace resolver {
namespace {

using test::EnvelopeSample;
using test::forward_samples;
using test::SimRecord;
using test::simulate;

SimConfig imperfect_sim(double seconds = 1.0) {
  SimConfig cfg;
  cfg.profile = {{seconds, 200.0, 200.0}};  // 10 resolver rev/s at p_r = 3, 200 samples/rev
  cfg.chain.set("amplitude_imbalance", "alpha", 0.03);
  cfg.chain.set("quadrature", "beta", 0.01);
  cfg.chain.set("offsets", "o_s", 0.005);
  cfg.chain.set("offsets", "o_c", -0.004);
  return cfg;
}

SinCosLeastSquares fit_records(const std::vector<SimRecord>& recs, const SinCosLsConfig& cfg, bool reference,
                               std::size_t count = 0) {
  SinCosLeastSquares ls(cfg);
  const std::size_t n = count == 0 ? recs.size() : count;
  for (std::size_t i = 0; i < n; ++i) {
    if (reference) {
      ls.add(recs[i].s, recs[i].c, recs[i].theta_ref);
    } else {
      ls.add(recs[i].s, recs[i].c);
    }
  }
  return ls;
}

TEST(SinCosLeastSquares, ReferenceFitRecoversCatalogParametersWithinCrlb) {
  const SimConfig cfg = imperfect_sim();
  const auto recs = simulate(cfg);
  SinCosLsConfig lc;
  lc.fit_reference_offset = false;  // the simulator's encoder is aligned with the resolver
  const auto fit = fit_records(recs, lc, true).solve();
  ASSERT_TRUE(fit.has_value());
  ASSERT_EQ(fit->method, SinCosFitMethod::kReference);
  const auto n = static_cast<std::int64_t>(recs.size());
  const CramerRao b = crlb_sincos(cfg.amplitude_counts, test::sim_sigma(cfg), n);
  const auto& ch = cfg.chain;
  EXPECT_NEAR(fit->alpha.value, ch.get("amplitude_imbalance", "alpha"), 5.0 * b.alpha);
  EXPECT_NEAR(fit->beta.value, ch.get("quadrature", "beta"), 5.0 * b.beta);
  EXPECT_NEAR(fit->o_s.value, ch.get("offsets", "o_s"), 5.0 * b.o_s);
  EXPECT_NEAR(fit->o_c.value, ch.get("offsets", "o_c"), 5.0 * b.o_c);
  EXPECT_NEAR(fit->amplitude.value, cfg.amplitude_counts, 5.0 * b.amplitude);
  // Reported standard errors: the data's own estimate of the bound. The residual
  // variance from 2000 samples is within ~3 % of the truth; 15 % allows the
  // O(alpha) change of the bound at the true point.
  EXPECT_NEAR(fit->alpha.std_error / b.alpha, 1.0, 0.15);
  EXPECT_NEAR(fit->beta.std_error / b.beta, 1.0, 0.15);
  EXPECT_NEAR(fit->o_s.std_error / b.o_s, 1.0, 0.15);
  EXPECT_NEAR(fit->residual_rms / test::sim_sigma(cfg), 1.0, 0.1);
}

TEST(SinCosLeastSquares, ReferenceFitFindsReferenceOffset) {
  const SimConfig cfg = imperfect_sim();
  auto recs = simulate(cfg);
  const double delta = 0.2;  // [rad] encoder mounted 0.2 rad behind the resolver
  for (auto& r : recs) r.theta_ref = wrap_2pi(r.theta_ref - delta);
  const auto fit = fit_records(recs, SinCosLsConfig{}, true).solve();
  ASSERT_TRUE(fit.has_value());
  const CramerRao b = crlb_sincos(cfg.amplitude_counts, test::sim_sigma(cfg), static_cast<std::int64_t>(recs.size()));
  EXPECT_NEAR(fit->reference_offset.value, delta, 5.0 * b.reference_offset);
  EXPECT_NEAR(fit->beta.value, cfg.chain.get("quadrature", "beta"), 5.0 * b.beta_with_offset);
  EXPECT_NEAR(fit->alpha.value, cfg.chain.get("amplitude_imbalance", "alpha"), 5.0 * b.alpha);
}

TEST(SinCosLeastSquares, ConicFitRecoversCatalogParametersWithinBlindCrlb) {
  const SimConfig cfg = imperfect_sim();
  const auto recs = simulate(cfg);
  const auto fit = fit_records(recs, SinCosLsConfig{}, false).solve();
  ASSERT_TRUE(fit.has_value());
  ASSERT_EQ(fit->method, SinCosFitMethod::kConic);
  const CramerRao b =
      crlb_sincos_blind(cfg.amplitude_counts, test::sim_sigma(cfg), static_cast<std::int64_t>(recs.size()));
  const auto& ch = cfg.chain;
  EXPECT_NEAR(fit->alpha.value, ch.get("amplitude_imbalance", "alpha"), 5.0 * b.alpha);
  EXPECT_NEAR(fit->beta.value, ch.get("quadrature", "beta"), 5.0 * b.beta);
  EXPECT_NEAR(fit->o_s.value, ch.get("offsets", "o_s"), 5.0 * b.o_s);
  EXPECT_NEAR(fit->o_c.value, ch.get("offsets", "o_c"), 5.0 * b.o_c);
  EXPECT_NEAR(fit->amplitude.value, cfg.amplitude_counts, 5.0 * b.amplitude);
  EXPECT_NEAR(fit->alpha.std_error / b.alpha, 1.0, 0.25);
  EXPECT_NEAR(fit->beta.std_error / b.beta, 1.0, 0.25);
  EXPECT_NEAR(fit->residual_rms / test::sim_sigma(cfg), 1.0, 0.15);
}

// Over 50 seeds the spread of each estimate is compared with the CRLB.
// With K = 50 samples of an estimator whose true std is s_true, (K - 1) s^2 / s_true^2
// is chi-square with 49 degrees of freedom. An efficient estimator (s_true = CRLB)
// exceeds 2 CRLB when chi2_49 > 4 * 49 = 196 (p ~ 1e-19) and falls below 0.5 CRLB
// when chi2_49 < 49 / 4 = 12.25 (p ~ 1e-9); an estimator 2x worse than the bound
// would pass the upper check only with p ~ 0.5. The seed set is fixed, so the
// test is deterministic; the margins say it is not tuned to these seeds.
struct Spread {
  double mean = 0.0, std = 0.0;
};
Spread spread(const std::vector<double>& v) {
  double m = 0.0;
  for (double x : v) m += x;
  m /= static_cast<double>(v.size());
  double s2 = 0.0;
  for (double x : v) s2 += (x - m) * (x - m);
  return {m, std::sqrt(s2 / static_cast<double>(v.size() - 1))};
}

TEST(SinCosLeastSquares, SpreadOverFiftySeedsIsWithinTwiceTheCrlb) {
  constexpr double kA = 26000.0, kSigma = 2.0;
  constexpr int kN = 400, kRevs = 2, kSeeds = 50;
  const ForwardChain chain = test::forward_chain({{"amplitude_imbalance", "alpha", 0.03},
                                                  {"quadrature", "beta", 0.01},
                                                  {"offsets", "o_s", 0.005},
                                                  {"offsets", "o_c", -0.004}});
  std::vector<double> ra, rb, ros, roc, ca, cb, cos_, coc;
  for (int seed = 1; seed <= kSeeds; ++seed) {
    const auto data = forward_samples(chain, kA, kSigma, kN, kRevs, 0.37 * seed, static_cast<std::uint64_t>(seed));
    SinCosLsConfig lc;
    lc.fit_reference_offset = false;
    SinCosLeastSquares ls(lc);
    for (const EnvelopeSample& d : data) ls.add(d.s, d.c, d.theta);
    const auto r = ls.solve_reference();
    const auto c = ls.solve_conic();
    ASSERT_TRUE(r && c);
    ra.push_back(r->alpha.value);
    rb.push_back(r->beta.value);
    ros.push_back(r->o_s.value);
    roc.push_back(r->o_c.value);
    ca.push_back(c->alpha.value);
    cb.push_back(c->beta.value);
    cos_.push_back(c->o_s.value);
    coc.push_back(c->o_c.value);
  }
  const CramerRao k = crlb_sincos(kA, kSigma, kN);
  const CramerRao bl = crlb_sincos_blind(kA, kSigma, kN);
  const auto check = [&](const std::vector<double>& v, double truth, double bound, const char* what) {
    const Spread s = spread(v);
    EXPECT_LE(s.std, 2.0 * bound) << what;
    EXPECT_GE(s.std, 0.5 * bound) << what;
    // Bias: the mean of 50 has std bound/sqrt(50); 5 of those.
    EXPECT_NEAR(s.mean, truth, 5.0 * bound / std::sqrt(kSeeds)) << what;
    std::printf("  %-16s std/CRLB = %.3f  bias/CRLB = %+.3f\n", what, s.std / bound, (s.mean - truth) / bound);
  };
  check(ra, 0.03, k.alpha, "ref alpha");
  check(rb, 0.01, k.beta, "ref beta");
  check(ros, 0.005, k.o_s, "ref o_s");
  check(roc, -0.004, k.o_c, "ref o_c");
  check(ca, 0.03, bl.alpha, "conic alpha");
  check(cb, 0.01, bl.beta, "conic beta");
  check(cos_, 0.005, bl.o_s, "conic o_s");
  check(coc, -0.004, bl.o_c, "conic o_c");
}

// alpha and K_3 both put a sin 2theta term into the R/D error (Hanselman 5 and 9:
// eps ~ (alpha/2 - K_3) sin 2theta); with alpha = 2 K_3 they cancel there exactly
// to first order. In the signals they differ: alpha scales the cos channel's
// fundamental, K_3 adds a 3theta term to both channels.
TEST(SinCosLeastSquares, TellsAlphaFromThirdHarmonic) {
  SimConfig cfg = imperfect_sim();
  cfg.chain.set("quadrature", "beta", 0.0);
  cfg.chain.set("offsets", "o_s", 0.0);
  cfg.chain.set("offsets", "o_c", 0.0);
  cfg.chain.set("amplitude_imbalance", "alpha", 0.01);
  cfg.chain.set("harmonics", "k3", 0.005);
  const auto recs = simulate(cfg);
  SinCosLsConfig lc;
  lc.harmonics = {3};
  lc.fit_reference_offset = false;
  const auto fit = fit_records(recs, lc, true).solve();
  ASSERT_TRUE(fit.has_value());
  ASSERT_EQ(fit->k.size(), 1U);
  const auto n = static_cast<std::int64_t>(recs.size());
  const CramerRao b = crlb_sincos(cfg.amplitude_counts, test::sim_sigma(cfg), n);
  // K_n's bound: each channel's projection on its n-theta pair has variance
  // 2 sigma^2/(N A^2); the two channels are averaged: sigma^2/(N A^2) = b.o_s^2.
  EXPECT_NEAR(fit->alpha.value, 0.01, 5.0 * b.alpha);
  EXPECT_NEAR(fit->k[0].value, 0.005, 5.0 * b.o_s);
  EXPECT_NEAR(fit->k[0].std_error / b.o_s, 1.0, 0.15);
  // Without the harmonic in the model alpha is still right (3theta is orthogonal
  // to the fundamental), but the residual is far above the noise.
  SinCosLsConfig plain;
  plain.fit_reference_offset = false;
  const auto fit0 = fit_records(recs, plain, true).solve();
  ASSERT_TRUE(fit0.has_value());
  EXPECT_GT(fit0->residual_rms, 10.0 * test::sim_sigma(cfg));
  EXPECT_LT(fit->residual_rms, 1.1 * test::sim_sigma(cfg));
  // ...while the R/D angle shows (almost) no 2theta error: the projection of
  // eps = theta - theta_rd on sin 2theta is below 2 % of alpha/2.
  double proj = 0.0;
  for (const auto& r : recs) proj += wrap_pi(r.theta - r.rd) * std::sin(2.0 * r.theta);
  proj *= 2.0 / static_cast<double>(recs.size());
  EXPECT_LT(std::abs(proj), 0.02 * 0.005);
}

// One resolver electrical revolution at the simulator's defaults (200 r/min,
// p_r = 3, 2 kHz: 200 samples) is enough for 1 % of alpha = 0.03 (3e-4):
// the CRLB there is 2 sigma/(A sqrt(200)) ~ 1.1e-5 (reference) and
// 2.8 sigma/(A sqrt(200)) ~ 1.6e-5 (conic).
TEST(SinCosLeastSquares, ConvergesWithinOneElectricalRevolution) {
  SimConfig cfg;
  cfg.profile = {{0.2, 200.0, 200.0}};
  cfg.chain.set("amplitude_imbalance", "alpha", 0.03);
  const auto recs = simulate(cfg);
  const std::size_t one_rev = static_cast<std::size_t>(cfg.sample_rate_hz / 10.0);  // 10 rev/s
  SinCosLsConfig lc;
  lc.fit_reference_offset = false;
  const auto ref = fit_records(recs, lc, true, one_rev).solve_reference();
  const auto conic = fit_records(recs, lc, false, one_rev).solve_conic();
  ASSERT_TRUE(ref && conic);
  EXPECT_LT(std::abs(ref->alpha.value - 0.03), 0.01 * 0.03);
  EXPECT_LT(std::abs(conic->alpha.value - 0.03), 0.01 * 0.03);
  std::printf("  after 1 rev: alpha ref %.6f conic %.6f (true 0.03)\n", ref->alpha.value, conic->alpha.value);
}

// Exponential forgetting follows a change: after 10 time constants (lambda =
// 0.99, 100 samples) the old alpha's weight is e^-10 ~ 5e-5.
TEST(SinCosLeastSquares, ForgettingTracksAChangeOfAlpha) {
  SinCosLsConfig lc;
  lc.forgetting = 0.99;
  lc.fit_reference_offset = false;
  SinCosLeastSquares ls(lc);
  const ForwardChain before = test::forward_chain({{"amplitude_imbalance", "alpha", 0.02}});
  const ForwardChain after = test::forward_chain({{"amplitude_imbalance", "alpha", 0.03}});
  for (const auto& d : forward_samples(before, 26000.0, 2.0, 2000, 10, 0.0, 7)) ls.add(d.s, d.c, d.theta);
  for (const auto& d : forward_samples(after, 26000.0, 2.0, 1000, 5, 0.0, 8)) ls.add(d.s, d.c, d.theta);
  const auto fit = ls.solve();
  ASSERT_TRUE(fit.has_value());
  // Effective samples n_eff = (1 + lambda)/(1 - lambda) = 199 for the bound.
  const CramerRao b = crlb_sincos(26000.0, 2.0, 199);
  EXPECT_NEAR(fit->alpha.value, 0.03, 5.0 * b.alpha + 0.01 * std::exp(-10.0));
  EXPECT_NEAR(fit->alpha.std_error / b.alpha, 1.0, 0.3);
  EXPECT_NEAR(fit->samples, 100.0, 1e-6);  // W = 1/(1 - lambda)
}

TEST(SinCosLeastSquares, RefusesTooFewSamplesAndBadConfig) {
  SinCosLeastSquares ls(SinCosLsConfig{});
  EXPECT_FALSE(ls.solve().has_value());
  for (int i = 0; i < 5; ++i) ls.add(std::sin(i), std::cos(i), i);
  EXPECT_FALSE(ls.solve().has_value());
  // All samples at one angle: a singular normal matrix, not a fit.
  SinCosLeastSquares one(SinCosLsConfig{});
  for (int i = 0; i < 100; ++i) one.add(0.5, 0.8, 0.56);
  EXPECT_FALSE(one.solve_reference().has_value());
  SinCosLsConfig bad;
  bad.forgetting = 0.0;
  EXPECT_THROW(SinCosLeastSquares{bad}, std::invalid_argument);
  bad.forgetting = 1.0;
  bad.harmonics = {1};
  EXPECT_THROW(SinCosLeastSquares{bad}, std::invalid_argument);
}

}  // namespace
}  // namespace resolver
