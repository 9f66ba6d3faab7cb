#include "daemon/core/effects/envelope_drift.h"

#include <array>

#include "daemon/core/effects/effect.h"

namespace resolver {

SinCos apply_envelope_drift(const EnvelopeDrift& p, double t, const SinCos& in) {
  const double gain = 1.0 + p.g * t;
  return {gain * in.s, gain * in.c};
}

double envelope_drift_radius(const EnvelopeDrift& p, double t) { return p.g * t; }

// ---- registry unit ------------------------------------------------------------
namespace {

// Range: ten times the fastest realistic warm-up (~1e-3 /s, envelope_drift.h), as the
// other effects' ranges leave room above the realistic, so the fit is never held at
// a bound by a real log.
constexpr std::array kParams{
    ParamInfo{.name = "g", .unit = "[1/s]",
              .description = "drift rate of the common sin/cos gain: both x (1 + g t), t from the first sample",
              .min = -0.01, .max = 0.01},
};
constexpr std::size_t kG = param_index(kParams, "g");

class EnvelopeDriftEffect final : public BasicEffect {
 public:
  EnvelopeDriftEffect()
      : BasicEffect({"envelope_drift", "sin and cos x (1 + g t): eps = 0, sin/cos radius + g t", "envelope_drift.h",
                     "the excitation amplitude drifts in time (the excitation winding or amplifier warming up): "
                     "both envelopes grow or shrink together, the sin/cos radius changes linearly in time and no "
                     "angle moves"},
                    kParams, EffectStage::kWindings) {}
  // No harmonic of any angle: the column is the time on the radius.
  [[nodiscard]] HarmonicOrders orders(std::span<const int> /*p*/) const override { return {}; }
  // Not envelope_only(): the fit's envelope spectrum is a function of the angle alone.
  void windings_in_time(Values v, WindingStage stage, double /*theta*/, double t, SinCos& env) const override {
    if (stage == WindingStage::kGain) env = apply_envelope_drift(EnvelopeDrift{v[kG]}, t, env);
  }
  void signature(const SignatureRow& row, const AngleBasis& /*b*/, Values /*v*/,
                 SignatureColumns& out) const override {
    out.col(kG) = SignalValues{.rd = 0.0, .sa = 0.0, .sr = row.t};
  }
};

}  // namespace

const Effect& envelope_drift_effect() {
  static const EnvelopeDriftEffect effect;
  return effect;
}

}  // namespace resolver
