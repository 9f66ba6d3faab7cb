// Each envelope effect's exact forward model (through an ideal converter,
// phi = atan2(s, c)) against the paper's small-parameter signature, within an
// approximation bound derived for that effect. The envelopes are the effect
// registry's forward chain (forward_chain.h), the signatures each effect header's
// closed form.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "daemon/core/angles.h"
#include "daemon/core/effects/amplitude_imbalance.h"
#include "daemon/core/effects/envelope_drift.h"
#include "daemon/core/effects/harmonics.h"
#include "daemon/core/effects/offsets.h"
#include "daemon/core/effects/quadrature.h"
#include "tests/unit/effects/chain_test_support.h"

namespace resolver {
namespace {

using test::exact_error;
using test::forward_chain;

constexpr int kGrid = 3600;  // theta grid over one electrical turn

/// Largest |exact - signature| over the grid, and the largest |signature|.
struct Residual {
  double max_residual = 0.0;
  double max_signature = 0.0;
};
template <typename Signature>
Residual residual(const ForwardChain& chain, Signature&& signature) {
  Residual r;
  for (int i = 0; i < kGrid; ++i) {
    const double theta = kTwoPi * (i + 0.37) / kGrid;  // off the symmetric points on purpose
    const double sig = signature(theta);
    r.max_residual = std::max(r.max_residual, std::abs(exact_error(chain, theta) - sig));
    r.max_signature = std::max(r.max_signature, std::abs(sig));
  }
  return r;
}

using test::atan2_second_order_bound;

TEST(EffectsSignatures, IdealChainHasNoError) {
  const ForwardChain ideal = forward_chain({});
  const Residual r = residual(ideal, [](double) { return 0.0; });
  EXPECT_LT(r.max_residual, 1e-15 * kTwoPi * 4);  // rounding of atan2 only
}

TEST(EffectsSignatures, AmplitudeImbalanceMatchesHanselmanEq5) {
  for (const double alpha : {-0.05, -0.01, 0.003, 0.01, 0.05}) {
    const ForwardChain chain = forward_chain({{"amplitude_imbalance", "alpha", alpha}});
    const Residual r =
        residual(chain, [&](double theta) { return amplitude_imbalance_error({{"alpha", alpha}}, theta); });
    // Exact: tan(phi) = tan(theta)/(1+alpha) gives
    //   eps = -sum_k q^k/k sin(2k theta), q = -alpha/(2+alpha),
    // so eps - (alpha/2) sin 2theta is bounded by the change of the first term,
    // |alpha/2 - alpha/(2+alpha)| ~ alpha^2/4, plus the tail sum_{k>=2} |q|^k/k = -ln(1-|q|) - |q|.
    const double q = std::abs(alpha / (2.0 + alpha));
    const double bound = std::abs(0.5 * alpha - alpha / (2.0 + alpha)) + (-std::log1p(-q) - q);
    EXPECT_LE(r.max_residual, bound * (1.0 + 1e-6) + 1e-15) << "alpha=" << alpha;
    // The bound is second order: far below the signature itself, so a wrong
    // sign or factor could not pass.
    EXPECT_LT(bound, 0.05 * r.max_signature) << "alpha=" << alpha;
    EXPECT_NEAR(r.max_signature, std::abs(alpha) / 2.0, 1e-6 * std::abs(alpha));
  }
}

TEST(EffectsSignatures, QuadratureSignMatchesExactModel) {
  // At theta = pi/2 the exact model is closed-form: phi = atan2(1, cos(pi/2 + beta))
  // = atan2(1, -sin beta) = pi/2 + atan(sin beta), so eps = theta - phi = -atan(sin beta)
  // ~= -beta. Hanselman eq. 7 as printed, +(beta/2)(1 - cos 2theta), would give +beta:
  // with eps = theta - phi the sign is negative.
  const double beta = 0.004;
  const ForwardChain chain = forward_chain({{"quadrature", "beta", beta}});
  const double theta = 0.5 * std::numbers::pi;
  EXPECT_NEAR(exact_error(chain, theta), -std::atan(std::sin(beta)), 1e-15);
  EXPECT_NEAR(quadrature_error({{"beta", beta}}, theta), -beta, 1e-15);
  // atan(sin beta) = beta - beta^3/2 + ...: the signature is right to third order here.
  EXPECT_NEAR(exact_error(chain, theta), quadrature_error({{"beta", beta}}, theta), beta * beta * beta);
}

TEST(EffectsSignatures, QuadratureMatchesHanselmanEq7) {
  for (const double beta : {-0.03, -0.004, 0.004, 0.01, 0.03}) {
    const ForwardChain chain = forward_chain({{"quadrature", "beta", beta}});
    const Residual r = residual(chain, [&](double theta) { return quadrature_error({{"beta", beta}}, theta); });
    // phi(beta) = atan2(sin theta, cos(theta + beta)); d phi/d beta = N/D with
    // N = sin theta sin(theta+beta), D = sin^2 theta + cos^2(theta+beta) = 1 - sin(2theta+beta) sin beta.
    // |N|, |N'|, |D'| <= 1, 1-|beta| <= D <= 1+|beta|, so |phi''| <= (2+|beta|)/(1-|beta|)^2 and the
    // Taylor remainder after the first-order term is <= beta^2/2 * (2+|beta|)/(1-|beta|)^2.
    const double b = std::abs(beta);
    const double bound = test::quadrature_remainder_bound(beta);
    EXPECT_LE(r.max_residual, bound) << "beta=" << beta;
    EXPECT_LT(bound, 0.05 * r.max_signature) << "beta=" << beta;
    EXPECT_NEAR(r.max_signature, b, 1e-6 * b);  // peak of (beta/2)(1 - cos 2theta) is beta
  }
}

TEST(EffectsSignatures, OffsetsMatchFirstOrderAtan2) {
  for (const auto& offsets : {std::pair{0.001, -0.002}, std::pair{-0.01, 0.0}, std::pair{0.0, 0.02}}) {
    const double o_s = offsets.first;  // (locals, not a structured binding: the lambda captures them)
    const double o_c = offsets.second;
    const ForwardChain chain = forward_chain({{"offsets", "o_s", o_s}, {"offsets", "o_c", o_c}});
    const Residual r =
        residual(chain, [&](double theta) { return offsets_error({{"o_s", o_s}, {"o_c", o_c}}, theta); });
    const double bound = atan2_second_order_bound(std::hypot(o_s, o_c));
    EXPECT_LE(r.max_residual, bound) << o_s << "," << o_c;
    EXPECT_LT(bound, 0.05 * r.max_signature);
    EXPECT_NEAR(r.max_signature, std::hypot(o_s, o_c), 1e-5 * std::hypot(o_s, o_c));  // 1x sinusoid
  }
}

TEST(EffectsSignatures, HarmonicsMatchHanselmanEq9) {
  const ForwardChain chain = forward_chain(
      {{"harmonics", "k0", 0.002}, {"harmonics", "k2", -0.001}, {"harmonics", "k3", 0.0015}, {"harmonics", "k7", 0.0005}});
  const HarmonicsParams h{{"k0", 0.002}, {"k2", -0.001}, {"k3", 0.0015}, {"k7", 0.0005}};
  const Residual r = residual(chain, [&](double theta) { return harmonics_error(h, theta); });
  // The harmonic part is an additive perturbation of length <= sqrt2 (|K_0| + sum |K_n|);
  // Hanselman eq. 9 is exactly its first-order atan2 term.
  const double d = std::numbers::sqrt2 * (0.002 + 0.001 + 0.0015 + 0.0005);
  const double bound = atan2_second_order_bound(d);
  EXPECT_LE(r.max_residual, bound);
  EXPECT_LT(bound, 0.05 * r.max_signature);
}

TEST(EffectsSignatures, OppositeSequenceHarmonicsLandOnNPlusOne) {
  // harmonics.h: an opposite-sign K_n_opp gives eps ~ -K_n_opp sin((n + 1) theta):
  // k3_opp lands on 4theta (where K_5 lands too), k2_opp on 3theta.
  for (const auto& [name, order] : {std::pair{"k3_opp", 3}, std::pair{"k2_opp", 2}}) {
    const double k = 0.002;
    const ForwardChain chain = forward_chain({{"harmonics", name, k}});
    HarmonicsParams h;
    h[harmonic_keys(order).opp] = k;
    const Residual r = residual(chain, [&](double theta) { return harmonics_error(h, theta); });
    EXPECT_LE(r.max_residual, atan2_second_order_bound(std::numbers::sqrt2 * k)) << name;
    // The grid's largest |sin((n + 1) theta)| is at least cos((n + 1) pi / kGrid): within 1e-5 relative.
    EXPECT_NEAR(r.max_signature, k, 1e-5 * k) << name;
    // The signature's own order: sin((n + 1) theta) with a minus sign at theta = pi / (2 (n + 1)).
    EXPECT_NEAR(harmonics_error(h, 0.5 * kPi / (order + 1)), -k, 1e-15) << name;
  }
}

TEST(EffectsSignatures, K3LandsOnTwoThetaLikeAlpha) {
  // Hanselman eq. 8-9: K_3 and alpha both give a 2theta error; K_3 = -alpha/2 mimics alpha to first order.
  const HarmonicsParams k3{{"k3", -0.002}};
  for (int i = 0; i < 64; ++i) {
    const double theta = kTwoPi * i / 64.0;
    EXPECT_NEAR(amplitude_imbalance_error({{"alpha", 0.004}}, theta), harmonics_error(k3, theta), 1e-15);
  }
  // ...but the envelopes differ at first order: the effects are told apart there.
  const SinCos a = forward_chain({{"amplitude_imbalance", "alpha", 0.004}}).envelopes(0.3);
  const SinCos k = forward_chain({{"harmonics", "k3", -0.002}}).envelopes(0.3);
  EXPECT_GT(std::abs(a.c - k.c) + std::abs(a.s - k.s), 1e-3);
}

TEST(EffectsSignatures, EnvelopeDriftScalesTheRadiusAndNoAngle) {
  // Both envelopes x (1 + g t) (envelope_drift.h): atan2 of a common positive factor is
  // the same angle, so the exact position error is 0 to rounding at every time, and
  // the radius is exactly 1 + g t.
  for (const double g : {-1e-3, 2e-4, 1e-3}) {
    const ForwardChain chain = forward_chain({{"envelope_drift", "g", g}});
    for (const double t : {0.0, 0.37, 3.0, 60.0}) {
      for (int i = 0; i < 360; ++i) {
        const double theta = kTwoPi * (i + 0.37) / 360.0;
        const SinCos sc = chain.envelopes(theta, t);
        ASSERT_NEAR(wrap_pi(theta - std::atan2(sc.s, sc.c)), 0.0, 1e-15) << "g=" << g << " t=" << t;
        ASSERT_NEAR(std::hypot(sc.s, sc.c) - 1.0, envelope_drift_radius({{"g", g}}, t), 1e-15)
            << "g=" << g << " t=" << t;
      }
    }
    // The radius moves by g t: at t = 3 s that is 3|g|, far above the rounding bound above.
    EXPECT_NEAR(envelope_drift_radius({{"g", g}}, 3.0), 3.0 * g, 1e-18);
  }
  // Common to both channels: with an imbalance the angle error is the imbalance's alone
  // at every time (the drift scales s and (1 + alpha) c alike), and the gain multiplies
  // the imbalance's radius: (1 + g t) hypot(s, (1 + alpha) c).
  const double alpha = 0.02, g = 1e-3, t = 2.5;
  const ForwardChain both = forward_chain({{"amplitude_imbalance", "alpha", alpha}, {"envelope_drift", "g", g}});
  const ForwardChain imbalance = forward_chain({{"amplitude_imbalance", "alpha", alpha}});
  for (int i = 0; i < 360; ++i) {
    const double theta = kTwoPi * (i + 0.37) / 360.0;
    const SinCos a = both.envelopes(theta, t), b = imbalance.envelopes(theta, t);
    ASSERT_NEAR(std::atan2(a.s, a.c), std::atan2(b.s, b.c), 1e-15) << theta;
    ASSERT_NEAR(std::hypot(a.s, a.c), (1.0 + g * t) * std::hypot(b.s, b.c), 1e-15) << theta;
  }
  // Time origin (envelope_drift.h): a log starting t0 later sees
  // (1 + g (t0 + t)) = (1 + g t0)(1 + g' t), g' = g / (1 + g t0): a constant gain (the
  // fit's amplitude nuisance) times the same kind of drift.
  const double t0 = 40.0, g_late = g / (1.0 + g * t0);
  const ForwardChain late = forward_chain({{"envelope_drift", "g", g_late}});
  for (const double tt : {0.0, 1.0, 3.0}) {
    const SinCos a = forward_chain({{"envelope_drift", "g", g}}).envelopes(0.7, t0 + tt);
    const SinCos b = late.envelopes(0.7, tt);
    EXPECT_NEAR(a.s, (1.0 + g * t0) * b.s, 1e-15) << tt;
    EXPECT_NEAR(a.c, (1.0 + g * t0) * b.c, 1e-15) << tt;
  }
}

TEST(EffectsSignatures, ComposedChainSuperposesToFirstOrder) {
  const ForwardChain chain = forward_chain({{"amplitude_imbalance", "alpha", 0.003},
                                            {"quadrature", "beta", 0.002},
                                            {"offsets", "o_s", 0.001},
                                            {"offsets", "o_c", -0.0015},
                                            {"harmonics", "k0", 0.0005},
                                            {"harmonics", "k3", 0.0008}});
  const HarmonicsParams h{{"k0", 0.0005}, {"k3", 0.0008}};
  // The first-order error of the composed chain is the sum of the individual
  // effects' signatures (what the deleted small_signal_error summed).
  const auto first_order = [&](double theta) {
    return amplitude_imbalance_error({{"alpha", 0.003}}, theta) + quadrature_error({{"beta", 0.002}}, theta) +
           offsets_error({{"o_s", 0.001}, {"o_c", -0.0015}}, theta) + harmonics_error(h, theta);
  };
  const Residual r = residual(chain, first_order);
  // Perturbation of the envelopes from the unit circle: d = d_lin + d_2 with
  // |d_2| <= beta^2/2 (cos(theta+beta) vs its linearisation) + |alpha| (|beta| + |H|)
  // (alpha times the perturbed cos channel). The signature sum is the first-order
  // atan2 term of d_lin (gradient norm 1), so
  //   |residual| <= |d_2| + d^2 / (2 (1-d)^2).
  const double alpha = 0.003;
  const double beta = 0.002;
  const double harm = std::numbers::sqrt2 * (0.0005 + 0.0008);
  const double off = std::hypot(0.001, 0.0015);
  const double d2 = 0.5 * beta * beta + alpha * (beta + harm);
  const double d = beta + alpha * (1.0 + beta + harm) + harm + off;
  const double bound = d2 + atan2_second_order_bound(d);
  EXPECT_LE(r.max_residual, bound);
  EXPECT_LT(bound, 0.05 * r.max_signature);
}

}  // namespace
}  // namespace resolver
