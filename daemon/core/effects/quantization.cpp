#include "daemon/core/effects/quantization.h"

#include <cmath>

#include "daemon/core/angles.h"

namespace resolver {

double quantization_lsb(int rd_bits) { return kTwoPi / std::ldexp(1.0, rd_bits); }

std::uint16_t quantize_rd_angle(double phi, int rd_bits) {
  const double steps = std::ldexp(1.0, rd_bits);  // 2^rd_bits codes per turn
  const auto code = static_cast<std::int64_t>(std::llround(wrap_2pi(phi) / kTwoPi * steps));
  // Rounding just below 2pi gives code == 2^rd_bits, which is angle 0.
  const std::int64_t wrapped = code & ((std::int64_t{1} << rd_bits) - 1);
  return static_cast<std::uint16_t>(wrapped << (Quantization::kMaxBits - rd_bits));
}

double rd_counts_to_angle(std::uint16_t counts) { return static_cast<double>(counts) * (kTwoPi / 65536.0); }

}  // namespace resolver
