#include "daemon/core/effects/backlash.h"

#include <algorithm>
#include <array>
#include <stdexcept>

#include "daemon/core/effects/effect.h"

namespace resolver {
namespace {

constexpr std::array kParams{
    ParamInfo{.name = "h", .unit = "[rad]", .description = "width of the play between reference and resolver (mechanical rad)",
              .min = 0.0, .max = 0.5},
};

class BacklashEffect final : public BasicEffect {
 public:
  BacklashEffect()
      : BasicEffect({"backlash",
                     "play h between reference and resolver: eps = p_r (h/2) sign(omega), an offset that flips with "
                     "the direction",
                     "backlash.h",
                     "play between the reference and the resolver (coupling, gearbox): a position error that jumps "
                     "between two levels when the direction reverses, at any speed"},
                    kParams, EffectStage::kMotion) {}
  [[nodiscard]] bool needs_reference() const override { return true; }
  [[nodiscard]] bool needs_speed_change() const override { return true; }
  [[nodiscard]] double seen_mech_angle(Values v, double theta_m, double omega_m, MotionState& state,
                                       bool commit) const override {
    const double half = 0.5 * v[0];
    if (half <= 0.0) return theta_m;
    // Start with the gap taken up in the direction of the first motion (forward at rest).
    const double previous = state.started ? state.value : theta_m - (omega_m < 0.0 ? -half : half);
    const double seen = std::clamp(previous, theta_m - half, theta_m + half);
    if (commit) {
      state.started = true;
      state.value = seen;
    }
    return seen;
  }
  void signature(const SignatureRow& row, const AngleBasis& /*b*/, Values /*v*/, SignatureColumns& out) const override {
    const double k = 0.5 * static_cast<double>(row.p_r) * row.direction;
    out.col(0) = shift_column(k, -k);
  }
};

}  // namespace

const Effect& backlash_effect() {
  static const BacklashEffect effect;
  return effect;
}

}  // namespace resolver
