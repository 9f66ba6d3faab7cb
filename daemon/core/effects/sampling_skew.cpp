#include "daemon/core/effects/sampling_skew.h"

#include <array>
#include <cmath>

#include "daemon/core/effects/effect.h"

namespace resolver {

double sampling_skew_beta(const SamplingSkewParams& p, double omega) { return omega * p["tau"]; }

double sampling_skew_error(const SamplingSkewParams& p, double theta, double omega) {
  // Quadrature signature (quadrature.h) with beta = omega tau.
  return -0.5 * sampling_skew_beta(p, omega) * (1.0 - std::cos(2.0 * theta));
}

SinCos compensate_sampling_skew(const SamplingSkewParams& p, const SinCos& sampled, double omega_hat) {
  // c = cos(theta + beta) = cos(theta) cos(beta) - sin(theta) sin(beta), s = sin(theta).
  const double beta = sampling_skew_beta(p, omega_hat);
  return {sampled.s, (sampled.c + sampled.s * std::sin(beta)) / std::cos(beta)};
}

// ---- registry unit ------------------------------------------------------------
namespace {

class SamplingSkewEffect final : public BasicEffect {
 public:
  SamplingSkewEffect()
      : BasicEffect({"sampling_skew",
                     "cos sampled tau after sin: like quadrature with beta = omega tau on the sampled sin/cos "
                     "(not the R/D angle); grows with speed",
                     "docs/ARCHITECTURE.md section 7, Hanselman eq. 6-7 via beta = omega tau",
                     "the cos channel is sampled after the sin channel: a quadrature-like error of the sin/cos pair "
                     "that grows with speed and that the R/D angle does not show"},
                    kSamplingSkewParams, EffectStage::kChannels) {}
  [[nodiscard]] bool needs_speed_change() const override { return true; }
  void channel_timing(Values v, ChannelTiming& timing) const override {
    timing.dsp_cos_dt += SamplingSkewParams(v)["tau"];
  }
  // c = C(theta(t + tau)) = cos(theta + omega tau): dc/dtau = -omega sin theta (first order).
  void signature(const SignatureRow& row, const AngleBasis& b, Values /*v*/, SignatureColumns& out) const override {
    out.col(SamplingSkewParams::index("tau")) = envelope_column(b, 0.0, 0.0, -row.omega * b.env_sin(1));
  }
};

}  // namespace

const Effect& sampling_skew_effect() {
  static const SamplingSkewEffect effect;
  return effect;
}

}  // namespace resolver
