// The exact, joint action of the envelope effects (Effect::envelope_only(): gain,
// quadrature, winding harmonics, offsets) on the signals the fit sees.
//
// Why: each effect's signature column is its first-order derivative about an ideal
// sensor. At real magnitudes (gain errors of 3-13 %, degrees of quadrature, offsets
// and harmonics of a few percent) the omitted terms are far above the noise floor:
// an imbalance alone has a 4 theta error of r^2/2, r = alpha / (2 + alpha)
// (the atan2 series, amplitude_imbalance.cpp: 1.1e-3 rad at alpha = 0.1), and two effects together have cross terms (alpha beta)
// no sum of single-effect columns carries.
//
// What: with the unit envelopes (s, c) of the seen angle phi taken through every
// envelope effect's windings() hook in stage order (forward_chain.h), the fit's
// signals are exactly (signature.h)
//   e(phi) = phi - atan2(s, c)      the angle error [rad] (sin/cos angle; the R/D
//                                    angle's through the converter's loop)
//   r(phi) = hypot(s, c) - 1        the radius deviation [1]
// Both are 2 pi periodic in phi with coefficients that do not depend on the sample,
// so they are tabulated once per parameter set on kGridPoints angles and expanded in
// Fourier series; a row then costs one sum over the orders present, and the R/D
// angle's error passes the converter order by order (AngleBasis::rd_sin: the loop is
// linear in the error). Each parameter's column is the same expansion of the exact
// derivative de/dp = (s dc/dp - c ds/dp) / rho^2, dr/dp = (s ds/dp + c dc/dp) / rho,
// with (ds, dc)/dp by central differences of the hooks (exact for the hooks linear in
// their parameter; O(h^2) = 1e-12 for quadrature's cos(theta + beta)).
//
// Accuracy: orders up to kGridPoints / 2 - 1 = 127 are resolved; an order above
// aliases. The series of every catalog effect falls as (magnitude / 2)^n, so at the
// catalog's largest values (0.5) order 40 is below 1e-12 rad; a coefficient under
// kDropBelow is dropped (far below any floor: a 24-bit converter's LSB is 3.7e-7 rad).
#pragma once

#include <span>
#include <vector>

#include "daemon/core/effects/effect.h"
#include "daemon/core/effects/signature.h"

namespace resolver {

/// One envelope effect with its values (every parameter of the effect).
struct EnvelopeMember {
  const Effect* effect = nullptr;
  std::span<const double> values;
};

/// A Fourier series in the seen angle phi of e(phi) and r(phi) (or their
/// derivatives), keeping the orders whose coefficients are not negligible:
///   e(phi) = sum_i e_cos[i] cos(k[i] phi) + e_sin[i] sin(k[i] phi), the same for r.
struct EnvelopeSeries {
  std::vector<int> k;
  std::vector<double> e_cos, e_sin, r_cos, r_sin;

  /// The signals of one row: sa and sr on the envelopes' angle, rd through the loop.
  [[nodiscard]] SignalValues at(const AngleBasis& basis) const;
  [[nodiscard]] bool empty() const { return k.empty(); }
  [[nodiscard]] int highest_order() const { return k.empty() ? 0 : k.back(); }
};

/// Grid, transform and truncation (header comment).
inline constexpr int kGridPoints = 256;
inline constexpr double kDropBelow = 1e-13;

/// The series of e and r for the members together.
[[nodiscard]] EnvelopeSeries envelope_series(std::span<const EnvelopeMember> members);

/// The series of de/dp and dr/dp for parameter `param` of member `member`, at the
/// members' values.
[[nodiscard]] EnvelopeSeries envelope_derivative_series(std::span<const EnvelopeMember> members, std::size_t member,
                                                        std::size_t param);

/// The unit envelopes of the seen angle phi through every member's windings hook, in
/// stage order (the simulator's chain: forward_chain.cpp).
[[nodiscard]] SinCos envelopes_through(std::span<const EnvelopeMember> members, double phi);

}  // namespace resolver
