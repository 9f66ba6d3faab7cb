#include "daemon/core/effects/quantization.h"

#include <cmath>

#include "daemon/core/angles.h"
#include "daemon/core/effects/effect.h"

namespace resolver {

double quantization_lsb(int rd_bits) { return kTwoPi / std::ldexp(1.0, rd_bits); }

std::uint16_t quantize_rd_angle(double phi, int rd_bits) {
  const double steps = std::ldexp(1.0, rd_bits);  // 2^rd_bits codes per turn
  const auto code = static_cast<std::int64_t>(std::llround(wrap_2pi(phi) / kTwoPi * steps));
  // Rounding just below 2pi gives code == 2^rd_bits, which is angle 0.
  const std::int64_t wrapped = code & ((std::int64_t{1} << rd_bits) - 1);
  return static_cast<std::uint16_t>(wrapped << (kRdFieldBits - rd_bits));
}

double rd_counts_to_angle(std::uint16_t counts) { return static_cast<double>(counts) * (kTwoPi / 65536.0); }

// ---- registry unit ------------------------------------------------------------
namespace {

class QuantizationEffect final : public BasicEffect {
 public:
  QuantizationEffect()
      : BasicEffect({"quantization", "R/D angle rounded to 2pi/2^rd_bits; uniform +-1/2 LSB", "Hanselman Table I",
                     "the converter's resolution: a uniform error of +-1/2 LSB that sets part of the floor"},
                    kQuantizationParams, EffectStage::kConverter) {}
  [[nodiscard]] bool fittable() const override { return false; }
  void converter(Values v, ConverterSpec& spec) const override {
    spec.rd_bits = static_cast<int>(QuantizationParams(v)["rd_bits"]);
  }
};

}  // namespace

const Effect& quantization_effect() {
  static const QuantizationEffect effect;
  return effect;
}

}  // namespace resolver
