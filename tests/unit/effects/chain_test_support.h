// Test helpers on the effect registry: a chain with a few parameters set, and
// the registry's composed forward model (forward_chain.h) built from it. Shared
// by the effects, estimation and sim tests; values go through ChainValues::set,
// so a range slip in a test throws instead of testing a value the CLI refuses.
#pragma once

#include <cmath>
#include <initializer_list>
#include <string_view>

#include "daemon/core/angles.h"
#include "daemon/core/effects/chain_values.h"
#include "daemon/core/effects/forward_chain.h"
#include "daemon/core/effects/sin_cos.h"

namespace resolver::test {

/// One parameter value: effect, parameter, value (in the parameter's unit).
struct Setting {
  std::string_view effect;
  std::string_view param;
  double value = 0.0;
};

/// Every effect neutral except `settings` (applied in order).
[[nodiscard]] inline ChainValues chain_values(std::initializer_list<Setting> settings) {
  ChainValues v;
  for (const Setting& s : settings) v.set(s.effect, s.param, s.value);
  return v;
}

/// The forward chain of chain_values(settings) for a resolver with p_r pole pairs on
/// a motor with p pole pairs (Hwang's bench: 3 and 3).
[[nodiscard]] inline ForwardChain forward_chain(std::initializer_list<Setting> settings, int p_r = 3, int p = 3) {
  return ForwardChain(chain_values(settings), p_r, p);
}

/// Exact position error eps = theta - phi [rad] at resolver angle theta [rad] of the
/// chain's envelopes through an ideal converter (phi = atan2(s, c)).
[[nodiscard]] inline double exact_error(const ForwardChain& chain, double theta) {
  return wrap_pi(theta - static_rd_angle(chain.envelopes(theta)));
}

/// Bound on the remainder of the quadrature signature (quadrature.h) after its
/// first-order term: phi(beta) = atan2(sin theta, cos(theta + beta)) has
/// |phi''| <= (2 + |beta|) / (1 - |beta|)^2 (signatures_test derives it), so
/// |eps_exact - eps_first_order| <= beta^2/2 (2 + |beta|) / (1 - |beta|)^2 [rad].
[[nodiscard]] inline double quadrature_remainder_bound(double beta) {
  const double b = std::abs(beta);
  return 0.5 * b * b * (2.0 + b) / ((1.0 - b) * (1.0 - b));
}

/// Bound on the second-order remainder of atan2 for an additive perturbation of
/// length d from the unit circle: the Hessian of atan2 has norm 1/r^2 and
/// r >= 1 - d on the segment, so |remainder| <= d^2 / (2 (1 - d)^2) [rad].
[[nodiscard]] inline double atan2_second_order_bound(double d) { return 0.5 * d * d / ((1.0 - d) * (1.0 - d)); }

}  // namespace resolver::test
