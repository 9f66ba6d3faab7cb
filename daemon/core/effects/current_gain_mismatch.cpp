#include "daemon/core/effects/current_gain_mismatch.h"

#include <array>
#include <cmath>
#include <numbers>

#include "daemon/core/effects/effect.h"

namespace resolver {

PhaseCurrents apply_current_gain_mismatch(const CurrentGainMismatchParams& p, const PhaseCurrents& in) {
  return {(1.0 + p["gain_a"]) * in.a, (1.0 + p["gain_b"]) * in.b, in.c};
}

DqCurrents current_gain_mismatch_dq_error(const CurrentGainMismatchParams& p, double i_d, double i_q,
                                          double theta_e) {
  // The Clarke error of the extra a and b parts, then Park (docs/ARCHITECTURE.md section 3).
  const PhaseCurrents i = ideal_phase_currents(i_d, i_q, theta_e);
  const double d_alpha = p["gain_a"] * i.a;
  const double d_beta = p["gain_b"] * i.b / std::numbers::sqrt3;
  const double ce = std::cos(theta_e);
  const double se = std::sin(theta_e);
  return {d_alpha * ce + d_beta * se, -d_alpha * se + d_beta * ce};
}

double current_gain_mismatch_ripple_2x(const CurrentGainMismatchParams& p, double i_d, double i_q) {
  const double u = p["gain_a"] - 0.5 * p["gain_b"];
  return 0.5 * std::hypot(i_d, i_q) * std::sqrt(u * u + p["gain_b"] * p["gain_b"] / 12.0);
}

PhaseCurrents compensate_current_gain_mismatch(const CurrentGainMismatchParams& p, const PhaseCurrents& measured) {
  return {measured.a / (1.0 + p["gain_a"]), measured.b / (1.0 + p["gain_b"]), measured.c};
}

}  // namespace resolver

// ---- registry unit ------------------------------------------------------------
namespace resolver {
namespace {

class CurrentGainMismatchEffect final : public BasicEffect {
 public:
  CurrentGainMismatchEffect()
      : BasicEffect({"current_gain_mismatch",
                     "i_a (1+gain_a), i_b (1+gain_b): dq ripple at 2x theta_e of amplitude |I|/2 sqrt((gain_a - "
                     "gain_b/2)^2 + gain_b^2/12)",
                     "docs/ARCHITECTURE.md section 7; current_gain_mismatch.h",
                     "the phase current sensors differ in gain: i_d and i_q ripple at 2x theta_e proportional to the "
                     "current, while the resolver signals are clean (so it is not the resolver's amplitude imbalance)"},
                    kCurrentGainMismatchParams, EffectStage::kCurrents) {}
  [[nodiscard]] HarmonicOrders orders(std::span<const int> /*p*/) const override { return {.theta_e = 2}; }
  [[nodiscard]] bool needs_reference() const override { return true; }
  void currents(Values v, CurrentStage stage, double /*theta_e*/, PhaseCurrents& i) const override {
    if (stage == CurrentStage::kSensorGain) i = apply_current_gain_mismatch(CurrentGainMismatchParams(v), i);
  }
  // Taken at the operating point (i_d0, i_q0): products of a gain error with its own
  // DC shift are second order (current_gain_mismatch.h).
  void signature(const SignatureRow& row, const AngleBasis& /*b*/, Values /*v*/, SignatureColumns& out) const override {
    const DqCurrents a =
        current_gain_mismatch_dq_error({{"gain_a", 1.0}, {"gain_b", 0.0}}, row.i_d0, row.i_q0, row.theta_e);
    const DqCurrents b =
        current_gain_mismatch_dq_error({{"gain_a", 0.0}, {"gain_b", 1.0}}, row.i_d0, row.i_q0, row.theta_e);
    out.col(CurrentGainMismatchParams::index("gain_a")) = SignalValues{.d = a.d, .q = a.q};
    out.col(CurrentGainMismatchParams::index("gain_b")) = SignalValues{.d = b.d, .q = b.q};
  }
};

}  // namespace

const Effect& current_gain_mismatch_effect() {
  static const CurrentGainMismatchEffect effect;
  return effect;
}

}  // namespace resolver
