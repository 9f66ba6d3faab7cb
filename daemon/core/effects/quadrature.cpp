#include "daemon/core/effects/quadrature.h"

#include <array>
#include <cmath>

#include "daemon/core/angles.h"
#include "daemon/core/effects/effect.h"
#include "daemon/core/effects/first_order_aliases.h"

namespace resolver {

SinCos quadrature_fundamental(const QuadratureParams& p, double theta) {
  return {std::sin(theta), std::cos(theta + p["beta"])};
}

double quadrature_error(const QuadratureParams& p, double theta) {
  return -0.5 * p["beta"] * (1.0 - std::cos(2.0 * theta));
}

// ---- registry unit ------------------------------------------------------------
namespace {

class QuadratureEffect final : public BasicEffect {
 public:
  QuadratureEffect()
      : BasicEffect({"quadrature", "cos channel cos(theta+beta); eps ~ -(beta/2)(1 - cos 2theta)",
                     "Hanselman eq. 6-7 (sign checked: eps = theta - phi)",
                     "the cos winding is not at 90 degrees: position error at 2 theta in phase with cos 2 theta plus "
                     "a constant, independent of speed, seen by the R/D angle and the sin/cos signals alike"},
                    kQuadratureParams, EffectStage::kWindings) {}
  // e^{-2i theta} of the envelopes: a 2 theta rotation's other side (first_order_aliases.h).
  [[nodiscard]] std::vector<std::string> first_order_aliases(std::span<const int> /*params*/, int p_r) const override {
    return rotation_terms_at_order(2, p_r);
  }
  void windings(Values v, WindingStage stage, double theta, SinCos& env) const override {
    if (stage == WindingStage::kFundamental) env = quadrature_fundamental(QuadratureParams(v), theta);
  }
  // rd: -(1/2)(1 - cos 2theta) per unit beta, through the converter (first order;
  // the omitted terms are O(beta^2)). c: the exact derivative of cos(theta + beta).
  void signature(const SignatureRow& /*row*/, const AngleBasis& b, Values v, SignatureColumns& out) const override {
    const double th = b.env_angle();
    const QuadratureParams p(v);
    out.col(p.index("beta")) = envelope_column(b, -0.5 * (1.0 - b.rd_cos(2)), 0.0, -std::sin(th + p["beta"]));
  }
  [[nodiscard]] bool envelope_only() const override { return true; }
  [[nodiscard]] bool linear_in_params() const override { return false; }
  void contribution(const SignatureRow& /*row*/, const AngleBasis& b, Values v, SignalValues& out) const override {
    const double th = b.env_angle();
    const QuadratureParams p(v);
    out.rd += -0.5 * p["beta"] * (1.0 - b.rd_cos(2));
    // The pair (sin th, cos(th + beta)) exactly.
    const double sn = b.env_sin(1), cq = std::cos(th + p["beta"]);
    out.sa += wrap_pi(th - std::atan2(sn, cq));
    out.sr += std::hypot(sn, cq) - 1.0;
  }
};

}  // namespace

const Effect& quadrature_effect() {
  static const QuadratureEffect effect;
  return effect;
}

}  // namespace resolver
