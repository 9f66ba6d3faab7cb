#include "daemon/core/effects/backlash.h"

#include <algorithm>
#include <array>
#include <stdexcept>

#include "daemon/core/effects/effect.h"
#include "daemon/core/effects/param_set.h"

namespace resolver {
namespace {

constexpr std::array kParams{
    ParamInfo{.name = "h", .unit = "[rad]", .description = "width of the play between reference and resolver (mechanical rad)",
              .min = 0.0, .max = 0.5, .nonlinear = true},
};
/// Typed, named access to the values of kParams (param_set.h).
using BacklashParams = ParamSet<kParams>;

/// [rad, mechanical] the play's lag in the direction of motion: h/2 once taken up,
/// running from -h/2 to +h/2 over the take-up after a reversal.
double eps_m(const SignatureRow& row, double h) {
  return row.since_reversal < h ? row.since_reversal - 0.5 * h : 0.5 * h;
}

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
  [[nodiscard]] Needs identifiable_with() const override { return Needs::kReversal; }
  [[nodiscard]] double seen_mech_angle(Values v, double theta_m, double omega_m, MotionState& state,
                                       bool commit) const override {
    const double half = 0.5 * BacklashParams(v)["h"];
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
  // Once the play is taken up: eps = p_r (h/2) sign(omega), a direction term.
  [[nodiscard]] bool has_motion_terms() const override { return true; }
  [[nodiscard]] MotionTerms motion_terms(Values v, int p_r) const override {
    return {.per_direction_rad = 0.5 * static_cast<double>(p_r) * BacklashParams(v)["h"]};
  }
  // Steady motion: eps = p_r (h/2) direction. During the take-up after a reversal
  // (travel D < h from the turning point) the resolver stands still: eps_m runs
  // from +h/2 to -h/2 of the new direction, eps = p_r direction (D - h/2).
  [[nodiscard]] bool shapes_basis() const override { return true; }
  void configure_basis(const SignatureRow& row, Values v, BasisTransform& t) const override {
    t.shift -= static_cast<double>(row.p_r) * row.direction * eps_m(row, BacklashParams(v)["h"]);
  }
  void signature(const SignatureRow& row, const AngleBasis& /*b*/, Values v, SignatureColumns& out) const override {
    const double k = 0.5 * static_cast<double>(row.p_r) * row.direction;
    const bool taking_up = row.since_reversal < BacklashParams(v)["h"];
    out.col(BacklashParams::index("h")) = shift_column(taking_up ? -k : k, taking_up ? k : -k);
  }
  [[nodiscard]] bool linear_in_params() const override { return false; }
  void contribution(const SignatureRow& row, const AngleBasis& /*b*/, Values v, SignalValues& out) const override {
    const double eps = static_cast<double>(row.p_r) * row.direction * eps_m(row, BacklashParams(v)["h"]);
    out += shift_column(eps, -eps);
  }
};

}  // namespace

const Effect& backlash_effect() {
  static const BacklashEffect effect;
  return effect;
}

}  // namespace resolver
