// Effect: inductance harmonics of the resolver windings.
//
// Cause: the winding distribution only approximates a sinusoid (Hanselman III.C).
// Forward model (Hanselman eq. 8), added to the fundamental envelopes, in two
// sequences:
//   same sign on both windings (Hanselman's K_n, a positive-sequence harmonic):
//     s += K_0 + sum_{n>=2} K_n sin(n theta),   c += K_0 + sum_{n>=2} K_n cos(n theta)
//   opposite sign (negative sequence: an odd nonlinearity acting on both channels,
//   e.g. saturation x - a x^3 gives K_3_opp = a/4 ... of the fundamental):
//     s += sum K_n_opp sin(n theta),            c -= sum K_n_opp cos(n theta)
// (K_1 = 1 is the fundamental itself, so it is not a parameter.)
// Each order has its own phase, as measured harmonics do: K_n sin(n theta + phi)
// = K_n cos(phi) sin(n theta) + K_n sin(phi) cos(n theta), so every order has a
// quadrature part K_n_q (k2_q .. k20_q, k2_opp_q .. k20_opp_q) beside its in-phase one:
//     s += K_n_q cos(n theta),  c -= K_n_q sin(n theta)          (same sign)
//     s += K_n_opp_q cos(n theta),  c += K_n_opp_q sin(n theta)  (opposite sign)
//   eps ~= -K_n_q cos((n - 1) theta) - K_n_opp_q cos((n + 1) theta).
// Signature, eps = theta - phi = sin(theta) dc - cos(theta) ds to first order:
//   eps ~= -sqrt(2) K_0 cos(theta + pi/4) - sum K_n sin((n - 1) theta)   (Hanselman eq. 9)
//          - sum K_n_opp sin((n + 1) theta)
// so K_3 lands on 2theta like amplitude imbalance, K_2 on 1theta like offsets, and
// K_3_opp, K_5 and K_7_opp ... on 4theta, 4theta, 8theta: only the sin/cos signals
// tell them apart (docs/ARCHITECTURE.md §7). Omitted terms are second order in the K's.
#pragma once

#include <array>

#include "daemon/core/effects/sin_cos.h"

namespace resolver {

struct Harmonics {
  /// Highest harmonic order a spec may set (k2 .. k20, k2_opp .. k20_opp).
  static constexpr int kMaxOrder = 20;
  /// [fraction of fundamental] inductive DC component K_0.
  double k0 = 0.0;
  /// [fraction of fundamental] K_n at index n for n = 2..kMaxOrder; k[0], k[1] are unused (stay 0).
  std::array<double, kMaxOrder + 1> k{};
  /// [fraction of fundamental] opposite-sequence K_n at index n for n = 2..kMaxOrder.
  std::array<double, kMaxOrder + 1> k_opp{};
  /// [fraction of fundamental] the quadrature parts of k and k_opp (header comment).
  std::array<double, kMaxOrder + 1> k_q{};
  std::array<double, kMaxOrder + 1> k_opp_q{};

  [[nodiscard]] bool active() const;
};

/// Forward model: the harmonic part (K_0 and K_n, n >= 2) of the envelopes at
/// resolver angle theta [rad], to be added to the fundamental.
[[nodiscard]] SinCos harmonics_part(const Harmonics& p, double theta);

/// Small-K position error eps = theta - phi [rad] (Hanselman eq. 9).
[[nodiscard]] double harmonics_error(const Harmonics& p, double theta);

/// The registry unit of this effect (registry.h).
class Effect;
[[nodiscard]] const Effect& harmonics_effect();

}  // namespace resolver
