#include "daemon/core/effects/amplitude_imbalance.h"

#include <array>
#include <cmath>
#include <stdexcept>

#include "daemon/core/angles.h"
#include "daemon/core/effects/effect.h"
#include "daemon/core/effects/first_order_aliases.h"

namespace resolver {

SinCos apply_amplitude_imbalance(const AmplitudeImbalanceParams& p, const SinCos& in) {
  return {in.s, (1.0 + p["alpha"]) * in.c};
}

double amplitude_imbalance_error(const AmplitudeImbalanceParams& p, double theta) {
  return 0.5 * p["alpha"] * std::sin(2.0 * theta);
}

}  // namespace resolver

// ---- registry unit ------------------------------------------------------------

namespace resolver {
namespace {

/// The R/D angle's error for a gain (1 + alpha) on the cos channel is exactly
///   eps = -sum_n (-r)^n / n sin(2 n theta),  r = alpha / (2 + alpha)
/// (phi = atan(tan theta / (1 + alpha)), the series of atan(k tan x)); first term
/// r sin 2theta ~ (alpha/2) sin 2theta (Hanselman eq. 5). Three terms leave
/// r^4/4 ~ alpha^4/64: below 1e-9 rad for |alpha| < 0.02.
constexpr int kSeriesTerms = 3;

class AmplitudeImbalanceEffect final : public BasicEffect {
 public:
  AmplitudeImbalanceEffect()
      : BasicEffect({"amplitude_imbalance", "cos channel x (1+alpha); eps ~ (alpha/2) sin 2theta",
                     "Hanselman eq. 4-5, Hwang eq. 6, 10, 15-16",
                     "a gain error of the cos channel: position error at 2 theta in phase with sin 2 theta, "
                     "independent of speed, and a cos-envelope amplitude off by alpha"},
                    kAmplitudeImbalanceParams, EffectStage::kWindings) {}
  // e^{-2i theta} of the envelopes: a 2 theta rotation's other side (first_order_aliases.h).
  [[nodiscard]] std::vector<std::string> first_order_aliases(std::span<const int> /*params*/, int p_r) const override {
    return rotation_terms_at_order(2, p_r);
  }
  void validate(Values v) const override {
    if (!(AmplitudeImbalanceParams(v)["alpha"] > -1.0)) {
      throw std::invalid_argument("amplitude_imbalance.alpha must be > -1 (a cos gain 1 + alpha > 0)");
    }
  }
  void windings(Values v, WindingStage stage, double /*theta*/, SinCos& env) const override {
    if (stage == WindingStage::kGain) env = apply_amplitude_imbalance(AmplitudeImbalanceParams(v), env);
  }
  void signature(const SignatureRow& /*row*/, const AngleBasis& b, Values v, SignatureColumns& out) const override {
    const double a = AmplitudeImbalanceParams(v)["alpha"];
    const double r = a / (2.0 + a);
    const double dr = 2.0 / ((2.0 + a) * (2.0 + a));
    // d/dr of -sum (-r)^n / n sin(2n theta) = sum (-r)^(n-1) sin(2n theta).
    double rd = 0.0, pw = 1.0;
    for (int n = 1; n <= kSeriesTerms; ++n) {
      rd += pw * b.rd_sin(2 * n);
      pw *= -r;
    }
    out.col(AmplitudeImbalanceParams::index("alpha")) = envelope_column(b, dr * rd, 0.0, b.env_cos(1));
  }
  [[nodiscard]] bool envelope_only() const override { return true; }
  [[nodiscard]] bool linear_in_params() const override { return false; }
  void contribution(const SignatureRow& /*row*/, const AngleBasis& b, Values v, SignalValues& out) const override {
    const double a = AmplitudeImbalanceParams(v)["alpha"];
    const double r = a / (2.0 + a);
    double pw = -r;
    for (int n = 1; n <= kSeriesTerms; ++n) {
      out.rd -= pw / n * b.rd_sin(2 * n);
      pw *= -r;
    }
    // The envelope pair (s, (1 + a) c) exactly: angle error -(phi - theta), radius - 1.
    const double sn = b.env_sin(1), cs = b.env_cos(1);
    out.sa += wrap_pi(b.env_angle() - std::atan2(sn, (1.0 + a) * cs));
    out.sr += std::hypot(sn, (1.0 + a) * cs) - 1.0;
  }
};

}  // namespace

const Effect& amplitude_imbalance_effect() {
  static const AmplitudeImbalanceEffect effect;
  return effect;
}

std::string amplitude_imbalance_alpha_name() {
  return std::string(amplitude_imbalance_effect().name()) + "." +
         std::string(AmplitudeImbalanceParams::info("alpha").name);
}

}  // namespace resolver
