#include "daemon/core/estimation/cramer_rao.h"

#include <cmath>
#include <limits>

namespace resolver {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

bool valid(double amplitude, double sigma, std::int64_t n) { return n > 0 && amplitude > 0.0 && sigma >= 0.0; }

}  // namespace

CramerRao crlb_sincos(double amplitude, double sigma, std::int64_t n) {
  if (!valid(amplitude, sigma, n)) return {kNaN, kNaN, kNaN, kNaN, kNaN, kNaN, kNaN};
  const double sn = sigma / std::sqrt(static_cast<double>(n));  // sigma / sqrt(N) [counts]
  const double rel = sn / amplitude;                             // sigma / (A sqrt(N)) [1]
  CramerRao b;
  b.amplitude = std::sqrt(2.0) * sn;      // var(A) = 2 sigma^2 / N
  b.alpha = 2.0 * rel;                    // var(alpha) = 4 sigma^2 / (N A^2)
  b.beta = std::sqrt(2.0) * rel;          // var(beta) = 2 sigma^2 / (N A^2)
  b.o_s = rel;                            // var(o) = sigma^2 / (N A^2)
  b.o_c = rel;
  b.beta_with_offset = 2.0 * rel;         // var(beta | delta unknown) = 4 sigma^2 / (N A^2)
  b.reference_offset = std::sqrt(2.0) * rel;  // var(delta) = 2 sigma^2 / (N A^2)
  return b;
}

CramerRao crlb_sincos_blind(double amplitude, double sigma, std::int64_t n) {
  if (!valid(amplitude, sigma, n)) return {kNaN, kNaN, kNaN, kNaN, kNaN, kNaN, kNaN};
  const double sn = sigma / std::sqrt(static_cast<double>(n));
  const double rel = sn / amplitude;
  CramerRao b;
  b.amplitude = std::sqrt(3.0) * sn;      // var(A) = 3 sigma^2 / N
  b.alpha = std::sqrt(8.0) * rel;         // var(alpha) = 8 sigma^2 / (N A^2)
  b.beta = std::sqrt(8.0) * rel;          // var(beta) = 8 sigma^2 / (N A^2)
  b.o_s = std::sqrt(2.0) * rel;           // var(o) = 2 sigma^2 / (N A^2)
  b.o_c = std::sqrt(2.0) * rel;
  b.beta_with_offset = kNaN;
  b.reference_offset = kNaN;
  return b;
}

}  // namespace resolver
