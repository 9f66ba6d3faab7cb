// The older estimators' results as Models (estimator_models.h): compensated through
// the one path (compensator.h), each must correct the angle as its own estimator's
// formula does, to the order the mapping is exact at.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "daemon/core/angles.h"
#include "daemon/core/effects/amplitude_imbalance.h"
#include "daemon/core/estimation/estimator_models.h"
#include "daemon/core/estimation/sample_processor.h"
#include "daemon/core/estimation/sincos_compensation.h"
#include "daemon/core/model/compensator.h"
#include "daemon/core/model/model_spec.h"
#include "tests/unit/effects/chain_test_support.h"

namespace resolver {
namespace {

constexpr int kAngles = 720;

double angle_at(int i) { return kTwoPi * (i + 0.37) / kAngles; }

TEST(EstimatorModels, HwangAlphaIsInvertedExactly) {
  // The exact measured angle of an imbalance alone (Hanselman eq. 4): the model's
  // inverse recovers the true angle; the fixed point leaves (d eps/d theta)^4 ~ alpha^4.
  const double alpha = 0.1;  // a real sensor's worst gain error
  Compensator c(hwang_model(alpha, 1e-5, 3, 3));
  double worst = 0.0;
  for (int i = 0; i < kAngles; ++i) {
    const double theta = angle_at(i);
    const double measured = wrap_2pi(std::atan2(std::sin(theta), (1.0 + alpha) * std::cos(theta)));
    worst = std::max(worst, std::abs(wrap_pi(c.correct(measured, 0.0, 0.0, 0.0, false) - theta)));
  }
  EXPECT_LT(worst, 2e-4);  // alpha^4 = 1e-4 bounds the fixed point's remainder [rad]
  const std::vector<ModelParameter> params = hwang_model(alpha, 1e-5, 3, 3).parameters();
  ASSERT_EQ(params.size(), 1U);
  EXPECT_EQ(params[0].name, amplitude_imbalance_alpha_name());
  EXPECT_DOUBLE_EQ(params[0].value, alpha);
  EXPECT_DOUBLE_EQ(params[0].std_error, 1e-5);
}

TEST(EstimatorModels, SinCosModelInvertsTheEnvelopesAtRealMagnitudes) {
  // A sensor with 5 % gain error, 20 mrad quadrature, 1-1.5 % offsets and two winding
  // harmonics (the registry's forward chain, unit amplitude). The sin/cos fit's
  // parameters are its effects' (SinCosFit), so the Model's inverse recovers the
  // true angle to the fixed point's remainder, where the older signal-domain
  // correction (one first-order step for the harmonics) leaves O(K^2) and more.
  const ForwardChain chain =
      test::forward_chain({{"amplitude_imbalance", "alpha", 0.05}, {"quadrature", "beta", -0.02},
                           {"offsets", "o_s", 0.01}, {"offsets", "o_c", -0.015}, {"harmonics", "k3", 0.004},
                           {"harmonics", "k5", -0.002}});
  SinCosFit f;
  f.amplitude = {1.0, 1e-6};
  f.alpha = {0.05, 1e-5};
  f.beta = {-0.02, 1e-5};
  f.o_s = {0.01, 1e-5};
  f.o_c = {-0.015, 1e-5};
  f.harmonic_orders = {3, 5};
  f.k = {{0.004, 1e-6}, {-0.002, 1e-6}};
  const SinCosCorrection corr = SinCosCorrection::from_fit(f);
  Compensator c(sincos_model(f, 3, 3));
  double worst_model = 0.0, worst_correction = 0.0;
  for (int i = 0; i < kAngles; ++i) {
    const double theta = angle_at(i);
    const SinCos raw = chain.envelopes(theta);
    const double via_model = c.correct(wrap_2pi(std::atan2(raw.s, raw.c)), 0.0, 0.0, 0.0, true);
    worst_model = std::max(worst_model, std::abs(wrap_pi(via_model - theta)));
    worst_correction = std::max(worst_correction, std::abs(wrap_pi(corrected_angle(corr, raw.s, raw.c) - theta)));
  }
  // (d eps/d theta)^4 x eps of errors ~0.05 rad: < 1e-6 rad.
  EXPECT_LT(worst_model, 1e-6);
  EXPECT_LE(worst_model, worst_correction);
}

AngleErrorFit fourier_fit(double scale) {
  AngleErrorFit f;
  f.max_order = 5;
  f.a0 = {0.3, 1e-6};  // the reference's zero: anywhere
  f.a.assign(6, {0.0, 1e-6});
  f.b.assign(6, {0.0, 1e-6});
  const double a[] = {0, 1.0, -0.8, 0.6, 0.0, -0.4};
  const double b[] = {0, -0.5, 0.7, -0.3, 0.2, 0.25};
  for (int n = 1; n <= 5; ++n) {
    f.a[static_cast<std::size_t>(n)].value = scale * a[n];
    f.b[static_cast<std::size_t>(n)].value = scale * b[n];
  }
  // The catalog mapping the fit computes (angle_error_fourier.h).
  f.alpha = {2.0 * f.a[2].value / (1.0 - f.a[2].value), 1e-6};
  f.beta = {2.0 * f.b[2].value, 1e-6};
  f.o_c = {f.a[1].value, 1e-6};
  f.o_s = {-f.b[1].value, 1e-6};
  return f;
}

/// Largest difference between the series evaluated at the measured angle and the
/// Model's inverse, over one turn.
double fourier_difference(double scale, int p_r, int p) {
  const AngleErrorFit f = fourier_fit(scale);
  Compensator c(fourier_model(f, p_r, p));
  double worst = 0.0;
  for (int i = 0; i < kAngles; ++i) {
    const double theta = angle_at(i);
    worst = std::max(worst, std::abs(wrap_pi(c.correct(theta, 0.0, 0.0, 0.0, false) - f.compensate(theta))));
  }
  return worst;
}

TEST(EstimatorModels, FourierSeriesMapsToTheCatalogAtFirstOrder) {
  // The series is in the measured angle, the Model in the true one, and the
  // effects' exact models carry their own second-order terms: the two compensations
  // differ by O(eps^2). Scaling the coefficients by 10 must scale the difference by
  // ~100; a wrong sign or order would leave a first-order difference (x10).
  for (const int p_r : {1, 3}) {
    const double small = fourier_difference(1e-4, p_r, 3);
    const double large = fourier_difference(1e-3, p_r, 3);
    EXPECT_LT(small, 1e-6) << "p_r " << p_r;  // (sum |c_n| ~ 5e-4) x (sum n |c_n| ~ 1.2e-3) ~ 6e-7 rad
    EXPECT_GT(large / std::max(small, 1e-300), 30.0) << "p_r " << p_r << ": not second order";
  }
}

TEST(EstimatorModels, FourierNamesAreTheEffectsParameters) {
  const Model m = fourier_model(fourier_fit(1e-3), 3, 3);
  std::vector<std::string> names;
  for (const ModelParameter& p : m.parameters()) names.push_back(p.name);
  for (const char* expected : {"amplitude_imbalance.alpha", "quadrature.beta", "offsets.o_s", "offsets.o_c",
                                      "harmonics.k4", "harmonics.k4_q", "harmonics.k6", "harmonics.k6_q",
                                      "mounting_offset.theta_0"}) {
    EXPECT_NE(std::find(names.begin(), names.end(), expected), names.end()) << expected;
  }
  // Every name an effect's own: reading them back gives the same model.
  EXPECT_EQ(ModelSpec::for_parameters(names).references(), m.spec().references());
}

TEST(EstimatorModels, ForParametersSkipsNamesNoEffectHas) {
  const std::vector<std::string> names{"amplitude_imbalance.alpha", "signal.amplitude", "harmonics.k3", "nope.x",
                                       "harmonics.k99", "nodot"};
  EXPECT_EQ(ModelSpec::for_parameters(names).references(),
            (std::vector<std::string>{"amplitude_imbalance", "harmonics"}));
}

TEST(EstimatorModels, EveryMethodCompensatesWithASeededModelUntilItsOwn) {
  // A saved calibration seeds every method (resolverd's state dir), not only kModel.
  for (const EstimatorMethod m : {EstimatorMethod::kHwangIntegral, EstimatorMethod::kSinCosLeastSquares,
                                  EstimatorMethod::kFourierReference, EstimatorMethod::kModel}) {
    ProcessorConfig cfg;
    cfg.method = m;
    SampleProcessor proc(cfg);
    EXPECT_FALSE(proc.compensating());
    proc.set_model(hwang_model(0.02, 1e-5, 3, 3), 0, 0.0);
    EXPECT_TRUE(proc.compensating()) << estimator_name(m);
    Sample in;
    in.has_rd = true;
    in.theta_rd = kPi / 4.0;  // eps of alpha/2 sin 2 theta is largest here
    const SampleOutput out = proc.process(in);
    EXPECT_NEAR(out.eps_hat, 0.01, 2e-4) << estimator_name(m);  // alpha/2, to O(alpha^2)
  }
}

}  // namespace
}  // namespace resolver
