#include "daemon/core/effects/offsets.h"

#include <array>
#include <cmath>

#include "daemon/core/effects/effect.h"

namespace resolver {

SinCos apply_offsets(const Offsets& p, const SinCos& in) { return {in.s + p.o_s, in.c + p.o_c}; }

double offsets_error(const Offsets& p, double theta) {
  return p.o_c * std::sin(theta) - p.o_s * std::cos(theta);
}

// ---- registry unit ------------------------------------------------------------
namespace {

constexpr std::array kParams{
    ParamInfo{.name = "o_s", .unit = "[fraction of amplitude]", .description = "DC offset of the sin channel",
              .min = -0.5, .max = 0.5},
    ParamInfo{.name = "o_c", .unit = "[fraction of amplitude]", .description = "DC offset of the cos channel",
              .min = -0.5, .max = 0.5},
};
constexpr std::size_t kOS = param_index(kParams, "o_s");
constexpr std::size_t kOC = param_index(kParams, "o_c");

class OffsetsEffect final : public BasicEffect {
 public:
  OffsetsEffect()
      : BasicEffect({"offsets", "additive sin/cos offsets; eps ~ o_c sin theta - o_s cos theta", "first-order atan2",
                     "DC offsets on the demodulated envelopes: position error at 1x theta, envelopes shifted by a "
                     "constant"},
                    kParams, EffectStage::kWindings) {}
  [[nodiscard]] bool envelope_only() const override { return true; }
  [[nodiscard]] HarmonicOrders orders(std::span<const int> /*p*/) const override { return {.theta = 1}; }
  void windings(Values v, WindingStage stage, double /*theta*/, SinCos& env) const override {
    if (stage == WindingStage::kOffset) env = apply_offsets(Offsets{v[kOS], v[kOC]}, env);
  }
  void signature(const SignatureRow& /*row*/, const AngleBasis& b, Values /*v*/,
                 SignatureColumns& out) const override {
    out.col(0) = envelope_column(b, -b.rd_cos(1), 1.0, 0.0);
    out.col(1) = envelope_column(b, b.rd_sin(1), 0.0, 1.0);
  }
};

}  // namespace

const Effect& offsets_effect() {
  static const OffsetsEffect effect;
  return effect;
}

}  // namespace resolver
