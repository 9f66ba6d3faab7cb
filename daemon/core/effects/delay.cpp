#include "daemon/core/effects/delay.h"

#include <array>
#include <cmath>

#include "daemon/core/effects/effect.h"
#include "daemon/core/effects/param_set.h"

namespace resolver {
namespace {

constexpr std::array kParams{
    ParamInfo{.name = "d", .unit = "[s]", .description = "delay of the resolver signals behind the reference",
              .min = -1.0, .max = 1.0, .nonlinear = true},
};
/// Typed, named access to the values of kParams (param_set.h).
using DelayParams = ParamSet<kParams>;

class DelayEffect final : public BasicEffect {
 public:
  DelayEffect()
      : BasicEffect({"delay",
                     "resolver signals of time t - d: eps = omega d, and every error harmonic shifted by omega d",
                     "delay.h",
                     "the resolver signals arrive late against the reference (bus, scope or filter latency): a "
                     "position error proportional to speed that flips with the direction"},
                    kParams, EffectStage::kMotion) {}
  [[nodiscard]] bool needs_reference() const override { return true; }
  [[nodiscard]] bool needs_speed_change() const override { return true; }
  [[nodiscard]] Needs identifiable_with() const override { return Needs::kSpeedChangeOrReversal; }
  [[nodiscard]] double resolver_time_shift(Values v) const override { return DelayParams(v)["d"]; }
  // eps = omega d at steady speed (delay.h).
  [[nodiscard]] bool has_motion_terms() const override { return true; }
  [[nodiscard]] MotionTerms motion_terms(Values v, int /*p_r*/) const override {
    return {.per_speed_s = DelayParams(v)["d"]};
  }
  void configure_basis(const SignatureRow& /*row*/, Values v, BasisTransform& t) const override {
    t.delay = DelayParams(v)["d"];
  }
  [[nodiscard]] bool shapes_basis() const override { return true; }
  [[nodiscard]] bool linear_in_params() const override { return false; }
  void contribution(const SignatureRow& row, const AngleBasis& /*b*/, Values v, SignalValues& out) const override {
    // theta(t) - theta(t - d): from the fit's rows when it has them (exact across a
    // speed step), else omega d - accel d^2 / 2.
    const double d = DelayParams(v)["d"];
    out.rd += d != 0.0 ? row.theta - row.theta_at(row.t - d) : 0.0;
    // The envelopes carry the late angle exactly: a rotation, radius unchanged.
    out.sa += d != 0.0 ? row.theta - row.theta_at(row.t - d) : 0.0;
  }
};

}  // namespace

const Effect& delay_effect() {
  static const DelayEffect effect;
  return effect;
}

}  // namespace resolver
