#include "daemon/core/effects/current_offsets.h"

#include <array>
#include <cmath>
#include <numbers>

#include "daemon/core/effects/effect.h"

namespace resolver {

PhaseCurrents apply_current_offsets(const CurrentOffsetsParams& p, const PhaseCurrents& in) {
  return {in.a + p["off_a"], in.b + p["off_b"], in.c};
}

DqCurrents current_offsets_dq_error(const CurrentOffsetsParams& p, double theta_e) {
  const double d_alpha = p["off_a"];
  const double d_beta = p["off_b"] / std::numbers::sqrt3;
  const double ce = std::cos(theta_e);
  const double se = std::sin(theta_e);
  return {d_alpha * ce + d_beta * se, -d_alpha * se + d_beta * ce};
}

double current_offsets_ripple_1x(const CurrentOffsetsParams& p) {
  return std::hypot(p["off_a"], p["off_b"] / std::numbers::sqrt3);
}

PhaseCurrents compensate_current_offsets(const CurrentOffsetsParams& p, const PhaseCurrents& measured) {
  return {measured.a - p["off_a"], measured.b - p["off_b"], measured.c};
}

}  // namespace resolver

// ---- registry unit ------------------------------------------------------------
namespace resolver {
namespace {

class CurrentOffsetsEffect final : public BasicEffect {
 public:
  CurrentOffsetsEffect()
      : BasicEffect({"current_offsets",
                     "i_a + off_a, i_b + off_b: dq ripple at 1x theta_e of amplitude hypot(off_a, off_b/sqrt3)",
                     "docs/ARCHITECTURE.md section 7; current_offsets.h",
                     "DC offsets of the phase current sensors: i_d and i_q ripple at 1x theta_e, a quarter period "
                     "apart, independent of load and speed; the resolver signals are clean"},
                    kCurrentOffsetsParams, EffectStage::kCurrents) {}
  [[nodiscard]] bool needs_reference() const override { return true; }
  void currents(Values v, CurrentStage stage, double /*theta_e*/, PhaseCurrents& i) const override {
    if (stage == CurrentStage::kSensorOffset) i = apply_current_offsets(CurrentOffsetsParams(v), i);
  }
  void signature(const SignatureRow& row, const AngleBasis& /*b*/, Values /*v*/, SignatureColumns& out) const override {
    // Per ampere of each offset, the other at zero.
    const DqCurrents a = current_offsets_dq_error({{"off_a", 1.0}, {"off_b", 0.0}}, row.theta_e);
    const DqCurrents b = current_offsets_dq_error({{"off_a", 0.0}, {"off_b", 1.0}}, row.theta_e);
    out.col(CurrentOffsetsParams::index("off_a")) = SignalValues{.d = a.d, .q = a.q};
    out.col(CurrentOffsetsParams::index("off_b")) = SignalValues{.d = b.d, .q = b.q};
  }
};

}  // namespace

const Effect& current_offsets_effect() {
  static const CurrentOffsetsEffect effect;
  return effect;
}

}  // namespace resolver
