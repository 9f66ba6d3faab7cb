#include "daemon/core/effects/offsets.h"

#include <cmath>

namespace resolver {

SinCos apply_offsets(const Offsets& p, const SinCos& in) { return {in.s + p.o_s, in.c + p.o_c}; }

double offsets_error(const Offsets& p, double theta) {
  return p.o_c * std::sin(theta) - p.o_s * std::cos(theta);
}

}  // namespace resolver
