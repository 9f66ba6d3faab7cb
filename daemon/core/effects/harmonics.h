// Effect: inductance harmonics of the resolver windings.
//
// Cause: the winding distribution only approximates a sinusoid (Hanselman III.C).
// Forward model (Hanselman eq. 8), added to the fundamental envelopes:
//   s += K_0 + sum_{n>=2} K_n sin(n theta)
//   c += K_0 + sum_{n>=2} K_n cos(n theta)
// (K_1 = 1 is the fundamental itself, so it is not a parameter.)
// Signature (Hanselman eq. 9), eps = theta - phi:
//   eps ~= -sqrt(2) K_0 cos(theta + pi/4) - sum_{n>=2} K_n sin((n - 1) theta)
// Note K_3 lands on 2theta like amplitude imbalance; only the sin/cos signals
// tell them apart (DESIGN 6). Omitted terms are second order in the K's.
#pragma once

#include <array>

#include "daemon/core/effects/sin_cos.h"

namespace resolver {

struct Harmonics {
  /// Highest harmonic order a spec may set (k2 .. k16).
  static constexpr int kMaxOrder = 16;
  /// [fraction of fundamental] inductive DC component K_0.
  double k0 = 0.0;
  /// [fraction of fundamental] K_n at index n for n = 2..kMaxOrder; k[0], k[1] are unused (stay 0).
  std::array<double, kMaxOrder + 1> k{};

  [[nodiscard]] bool active() const;
};

/// Forward model: the harmonic part (K_0 and K_n, n >= 2) of the envelopes at
/// resolver angle theta [rad], to be added to the fundamental.
[[nodiscard]] SinCos harmonics_part(const Harmonics& p, double theta);

/// Small-K position error eps = theta - phi [rad] (Hanselman eq. 9).
[[nodiscard]] double harmonics_error(const Harmonics& p, double theta);

}  // namespace resolver
