#include "daemon/core/effects/quadrature.h"

#include <cmath>

namespace resolver {

SinCos quadrature_fundamental(const Quadrature& p, double theta) {
  return {std::sin(theta), std::cos(theta + p.beta)};
}

double quadrature_error(const Quadrature& p, double theta) {
  return -0.5 * p.beta * (1.0 - std::cos(2.0 * theta));
}

}  // namespace resolver
