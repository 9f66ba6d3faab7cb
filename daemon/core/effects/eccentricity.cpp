#include "daemon/core/effects/eccentricity.h"

#include <array>
#include <cmath>
#include <stdexcept>

#include "daemon/core/effects/effect.h"
#include "daemon/core/effects/first_order_aliases.h"

namespace resolver {

double eccentric_angle(const EccentricityParams& p, double theta_m) {
  return theta_m + p["e"] * std::sin(theta_m + p["phase"]);
}

double eccentricity_error(const EccentricityParams& p, double theta_m) {
  return -p["e"] * std::sin(theta_m + p["phase"]);
}

double compensate_eccentricity(const EccentricityParams& p, double theta_seen_m) {
  if (p["e"] == 0.0) return theta_seen_m;  // a phase alone is no eccentricity (the effect's active())
  // theta_m = theta_seen_m - e sin(theta_m + phase): the map's Lipschitz constant is
  // |e|, so each iteration multiplies the error by <= |e|. Starting from theta_seen_m
  // (error <= |e|), 60 iterations reach |e|^61 <= 0.5^61 ~ 4e-19 for |e| <= 0.5; stop
  // early once the update is at rounding level.
  double theta_m = theta_seen_m;
  for (int i = 0; i < 60; ++i) {
    const double next = theta_seen_m - p["e"] * std::sin(theta_m + p["phase"]);
    const double change = std::abs(next - theta_m);
    theta_m = next;
    if (change <= 1e-16 * (1.0 + std::abs(theta_seen_m))) break;
  }
  return theta_m;
}

}  // namespace resolver

// ---- registry unit ------------------------------------------------------------
namespace resolver {
namespace {

class EccentricityEffect final : public BasicEffect {
 public:
  EccentricityEffect()
      : BasicEffect({"eccentricity",
                     "resolver sees theta_m + e sin(theta_m + phase): eps = -p_r e sin(theta_m + phase), 1x mechanical",
                     "docs/ARCHITECTURE.md section 7; eccentricity.h",
                     "the rotor is not concentric: a 1x mechanical harmonic of the position error (order 1/p_r of "
                     "theta), only visible against the reference encoder"},
                    kEccentricityParams, EffectStage::kMotion) {}
  [[nodiscard]] HarmonicOrders orders(std::span<const int> /*p*/) const override { return {.theta_m = 1}; }
  [[nodiscard]] bool needs_reference() const override { return true; }
  // At p_r = 1 its 1x mechanical is 1 theta: the order-1 winding terms' alias.
  [[nodiscard]] std::vector<std::string> first_order_aliases(std::span<const int> /*params*/, int p_r) const override {
    return p_r == 1 ? winding_terms_at_order(1) : std::vector<std::string>{};
  }
  [[nodiscard]] bool active(Values v) const override { return EccentricityParams(v)["e"] != 0.0; }
  void validate(Values v) const override {
    if (!(std::abs(EccentricityParams(v)["e"]) < 1.0)) {
      throw std::invalid_argument(
          "eccentricity.e must be in (-1, 1) mechanical rad so the resolver keeps turning one way");
    }
  }
  [[nodiscard]] double seen_mech_angle(Values v, double theta_m, double /*omega_m*/, MotionState& /*state*/,
                                       bool /*commit*/) const override {
    return eccentric_angle(EccentricityParams(v), theta_m);
  }
  // Columns for x = e cos(phase), y = e sin(phase): e sin(theta_m + phase) = x sin theta_m + y cos theta_m.
  // The polar pair's columns (effect.h, Polar): x in the amplitude's, y in the phase's.
  void signature(const SignatureRow& row, const AngleBasis& b, Values /*v*/, SignatureColumns& out) const override {
    const double pr = row.p_r;
    out.col(EccentricityParams::index("e")) = shift_column(-pr * b.rd_mech_sin(1), pr * b.env_mech_sin(1));
    out.col(EccentricityParams::index("phase")) = shift_column(-pr * b.rd_mech_cos(1), pr * b.env_mech_cos(1));
  }
  [[nodiscard]] bool linear_in_params() const override { return false; }
  [[nodiscard]] bool shapes_basis() const override { return true; }
  void configure_basis(const SignatureRow& row, Values v, BasisTransform& t) const override {
    const EccentricityParams p(v);
    t.shift += static_cast<double>(row.p_r) * p["e"] * std::sin(row.theta_m + p["phase"]);
  }
  void contribution(const SignatureRow& row, const AngleBasis& b, Values v, SignalValues& out) const override {
    const EccentricityParams p(v);
    const double x = p["e"] * std::cos(p["phase"]), y = p["e"] * std::sin(p["phase"]);
    const double pr = row.p_r;
    out += shift_column(-pr * (x * b.rd_mech_sin(1) + y * b.rd_mech_cos(1)),
                        pr * (x * b.env_mech_sin(1) + y * b.env_mech_cos(1)));
  }
};

}  // namespace

const Effect& eccentricity_effect() {
  static const EccentricityEffect effect;
  return effect;
}

}  // namespace resolver
