// The closed-form CRLB (cramer_rao.h) against the Fisher matrix built
// numerically from the effect registry's forward chain: finite-difference
// gradients of (s, c) at N uniformly spread angles, F = sum J^T J / sigma^2,
// inverted with Eigen. The unknown-angle case eliminates each sample's angle by
// projecting out the tangential gradient (the per-sample Schur complement).
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>

#include "daemon/core/angles.h"
#include "tests/unit/effects/chain_test_support.h"
#include "daemon/core/estimation/cramer_rao.h"

namespace resolver {
namespace {

// x = (A, alpha, beta, o_s, o_c, delta); returns (s, c) [counts] at angle theta.
Eigen::Vector2d model(const Eigen::VectorXd& x, double theta) {
  const ForwardChain chain = test::forward_chain(
      {{"amplitude_imbalance", "alpha", x(1)}, {"quadrature", "beta", x(2)}, {"offsets", "o_s", x(3)}, {"offsets", "o_c", x(4)}});
  const double delta = x.size() > 5 ? x(5) : 0.0;
  const SinCos sc = chain.envelopes(theta + delta);
  return {x(0) * sc.s, x(0) * sc.c};
}

struct NumericFisher {
  Eigen::MatrixXd known;  // angles known
  Eigen::MatrixXd blind;  // angles unknown (nuisance eliminated)
};

NumericFisher fisher(const Eigen::VectorXd& x, double sigma, int n) {
  const auto p = x.size();
  NumericFisher f{Eigen::MatrixXd::Zero(p, p), Eigen::MatrixXd::Zero(p, p)};
  for (int i = 0; i < n; ++i) {
    const double theta = 0.1 + kTwoPi * i / n;  // one whole revolution, uniform
    Eigen::MatrixXd j(2, p);
    for (Eigen::Index k = 0; k < p; ++k) {
      const double h = 1e-6 * (1.0 + std::abs(x(k)));
      Eigen::VectorXd xp = x, xm = x;
      xp(k) += h;
      xm(k) -= h;
      j.col(k) = (model(xp, theta) - model(xm, theta)) / (2.0 * h);
    }
    const double ht = 1e-6;
    const Eigen::Vector2d jt = (model(x, theta + ht) - model(x, theta - ht)) / (2.0 * ht);
    const Eigen::Matrix2d proj = Eigen::Matrix2d::Identity() - jt * jt.transpose() / jt.squaredNorm();
    f.known += j.transpose() * j / (sigma * sigma);
    f.blind += j.transpose() * proj * j / (sigma * sigma);
  }
  return f;
}

Eigen::VectorXd crlb_std(const Eigen::MatrixXd& f) { return f.inverse().diagonal().cwiseSqrt(); }

constexpr double kA = 26000.0;  // [counts] the simulator's amplitude
constexpr double kSigma = 2.0;  // [counts] the simulator's noise
constexpr int kN = 720;

TEST(CramerRao, ClosedFormMatchesNumericFisherKnownAngles) {
  Eigen::VectorXd x(5);
  x << kA, 0.0, 0.0, 0.0, 0.0;
  const Eigen::VectorXd num = crlb_std(fisher(x, kSigma, kN).known);
  const CramerRao b = crlb_sincos(kA, kSigma, kN);
  // Finite differences are exact to ~1e-9 relative here; the closed form is exact
  // for uniform angles (N > 4 makes the trigonometric sums exact).
  EXPECT_NEAR(num(0) / b.amplitude, 1.0, 1e-6);
  EXPECT_NEAR(num(1) / b.alpha, 1.0, 1e-6);
  EXPECT_NEAR(num(2) / b.beta, 1.0, 1e-6);
  EXPECT_NEAR(num(3) / b.o_s, 1.0, 1e-6);
  EXPECT_NEAR(num(4) / b.o_c, 1.0, 1e-6);
  // The numbers themselves: var(alpha) = 4 sigma^2 / (N A^2).
  EXPECT_NEAR(b.alpha, 2.0 * kSigma / (kA * std::sqrt(kN)), 1e-15);
}

TEST(CramerRao, ReferenceOffsetDoublesBetaVariance) {
  Eigen::VectorXd x(6);
  x << kA, 0.0, 0.0, 0.0, 0.0, 0.0;
  const Eigen::VectorXd num = crlb_std(fisher(x, kSigma, kN).known);
  const CramerRao b = crlb_sincos(kA, kSigma, kN);
  EXPECT_NEAR(num(1) / b.alpha, 1.0, 1e-6);  // alpha is not coupled to delta
  EXPECT_NEAR(num(2) / b.beta_with_offset, 1.0, 1e-6);
  EXPECT_NEAR(num(5) / b.reference_offset, 1.0, 1e-6);
  EXPECT_NEAR(b.beta_with_offset / b.beta, std::sqrt(2.0), 1e-12);
}

TEST(CramerRao, ClosedFormMatchesNumericFisherUnknownAngles) {
  Eigen::VectorXd x(5);
  x << kA, 0.0, 0.0, 0.0, 0.0;
  const Eigen::VectorXd num = crlb_std(fisher(x, kSigma, kN).blind);
  const CramerRao b = crlb_sincos_blind(kA, kSigma, kN);
  EXPECT_NEAR(num(0) / b.amplitude, 1.0, 1e-6);
  EXPECT_NEAR(num(1) / b.alpha, 1.0, 1e-6);
  EXPECT_NEAR(num(2) / b.beta, 1.0, 1e-6);
  EXPECT_NEAR(num(3) / b.o_s, 1.0, 1e-6);
  EXPECT_NEAR(num(4) / b.o_c, 1.0, 1e-6);
}

TEST(CramerRao, NominalBoundHoldsToFirstOrderAtRealisticImperfections) {
  // At alpha = 3 %, beta = 0.02 rad, offsets 1 % the exact bound moves by
  // O(alpha, beta, o) relative; 10 % covers 3x the largest of them.
  Eigen::VectorXd x(5);
  x << kA, 0.03, 0.02, 0.01, -0.01;
  const NumericFisher f = fisher(x, kSigma, kN);
  const Eigen::VectorXd known = crlb_std(f.known);
  const Eigen::VectorXd blind = crlb_std(f.blind);
  const CramerRao b = crlb_sincos(kA, kSigma, kN);
  const CramerRao bb = crlb_sincos_blind(kA, kSigma, kN);
  EXPECT_NEAR(known(1) / b.alpha, 1.0, 0.1);
  EXPECT_NEAR(known(2) / b.beta, 1.0, 0.1);
  EXPECT_NEAR(known(3) / b.o_s, 1.0, 0.1);
  EXPECT_NEAR(blind(1) / bb.alpha, 1.0, 0.1);
  EXPECT_NEAR(blind(2) / bb.beta, 1.0, 0.1);
  EXPECT_NEAR(blind(4) / bb.o_c, 1.0, 0.1);
}

TEST(CramerRao, InvalidInputsGiveNaN) {
  EXPECT_TRUE(std::isnan(crlb_sincos(kA, kSigma, 0).alpha));
  EXPECT_TRUE(std::isnan(crlb_sincos(0.0, kSigma, 10).alpha));
  EXPECT_TRUE(std::isnan(crlb_sincos_blind(kA, -1.0, 10).beta));
}

}  // namespace
}  // namespace resolver
