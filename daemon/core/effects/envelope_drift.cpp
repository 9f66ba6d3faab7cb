#include "daemon/core/effects/envelope_drift.h"

#include <array>

#include "daemon/core/effects/effect.h"

namespace resolver {

SinCos apply_envelope_drift(const EnvelopeDriftParams& p, double t, const SinCos& in) {
  const double gain = 1.0 + p["g"] * t;
  return {gain * in.s, gain * in.c};
}

double envelope_drift_radius(const EnvelopeDriftParams& p, double t) { return p["g"] * t; }

// ---- registry unit ------------------------------------------------------------
namespace {

class EnvelopeDriftEffect final : public BasicEffect {
 public:
  EnvelopeDriftEffect()
      : BasicEffect({"envelope_drift", "sin and cos x (1 + g t): eps = 0, sin/cos radius + g t", "envelope_drift.h",
                     "the excitation amplitude drifts in time (the excitation winding or amplifier warming up): "
                     "both envelopes grow or shrink together, the sin/cos radius changes linearly in time and no "
                     "angle moves"},
                    kEnvelopeDriftParams, EffectStage::kWindings) {}
  // No harmonic of any angle: the column is the time on the radius.
  [[nodiscard]] HarmonicOrders orders(std::span<const int> /*p*/) const override { return {}; }
  // Not envelope_only(): the fit's envelope spectrum is a function of the angle alone.
  void windings_in_time(Values v, WindingStage stage, double /*theta*/, double t, SinCos& env) const override {
    if (stage == WindingStage::kGain) env = apply_envelope_drift(EnvelopeDriftParams(v), t, env);
  }
  void signature(const SignatureRow& row, const AngleBasis& /*b*/, Values /*v*/,
                 SignatureColumns& out) const override {
    out.col(EnvelopeDriftParams::index("g")) = SignalValues{.rd = 0.0, .sa = 0.0, .sr = row.t};
  }
};

}  // namespace

const Effect& envelope_drift_effect() {
  static const EnvelopeDriftEffect effect;
  return effect;
}

}  // namespace resolver
