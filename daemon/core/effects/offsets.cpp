#include "daemon/core/effects/offsets.h"

#include <array>
#include <cmath>

#include "daemon/core/effects/effect.h"
#include "daemon/core/effects/first_order_aliases.h"

namespace resolver {

SinCos apply_offsets(const OffsetsParams& p, const SinCos& in) { return {in.s + p["o_s"], in.c + p["o_c"]}; }

double offsets_error(const OffsetsParams& p, double theta) {
  return p["o_c"] * std::sin(theta) - p["o_s"] * std::cos(theta);
}

// ---- registry unit ------------------------------------------------------------
namespace {

class OffsetsEffect final : public BasicEffect {
 public:
  OffsetsEffect()
      : BasicEffect({"offsets", "additive sin/cos offsets; eps ~ o_c sin theta - o_s cos theta", "first-order atan2",
                     "DC offsets on the demodulated envelopes: position error at 1x theta, envelopes shifted by a "
                     "constant"},
                    kOffsetsParams, EffectStage::kWindings) {}
  [[nodiscard]] bool envelope_only() const override { return true; }
  [[nodiscard]] HarmonicOrders orders(std::span<const int> /*p*/) const override { return {.theta = 1}; }
  // The constant of a 1 theta rotation of the envelopes (first_order_aliases.h).
  [[nodiscard]] std::vector<std::string> first_order_aliases(std::span<const int> /*params*/, int p_r) const override {
    return rotation_terms_at_order(1, p_r);
  }
  void windings(Values v, WindingStage stage, double /*theta*/, SinCos& env) const override {
    if (stage == WindingStage::kOffset) env = apply_offsets(OffsetsParams(v), env);
  }
  void signature(const SignatureRow& /*row*/, const AngleBasis& b, Values /*v*/,
                 SignatureColumns& out) const override {
    out.col(OffsetsParams::index("o_s")) = envelope_column(b, -b.rd_cos(1), 1.0, 0.0);
    out.col(OffsetsParams::index("o_c")) = envelope_column(b, b.rd_sin(1), 0.0, 1.0);
  }
};

}  // namespace

const Effect& offsets_effect() {
  static const OffsetsEffect effect;
  return effect;
}

}  // namespace resolver
