// Which terms land on the same harmonics of the envelopes at first order, at a log's p_r.
//
// A rotation of the seen angle by delta = a sin(m theta) + b cos(m theta) (a mechanical
// pair of order n = m p_r, eccentricity at p_r = 1) multiplies the envelopes' complex
// signal e^{i theta} by 1 + i delta: terms on e^{i (1 + m) theta} and e^{i (1 - m) theta}.
// Those are exactly the first-order columns of the winding terms of that order (Hanselman
// eq. 8, harmonics.h): the same-sign harmonic K_{m+1} with its quadrature, and on the
// other side the opposite-sign K_{m-1}_opp, which is amplitude_imbalance and quadrature
// at m = 2 (K_1_opp) and the offsets at m = 1 (a constant). Two columns of the pair in a
// space of four: a model holding the pair and a winding term of its order is separable
// only at second order (a rotation keeps the radius, winding terms do not), and the one
// of two aliases that is not in the sensor leaves a second-order remainder that draws
// spurious candidates (docs/ACCURACY.md "Aliases").
#pragma once

#include <string>
#include <vector>

namespace resolver {

/// The winding terms on e^{i (1 +- m) theta}, as effect references (m >= 1).
[[nodiscard]] std::vector<std::string> winding_terms_at_order(int m);

/// The terms that rotate the seen angle by m theta at this p_r (a mechanical pair of
/// order m p_r; eccentricity too where that order is 1), as effect references; none when
/// m p_r is beyond the catalog's mechanical orders.
[[nodiscard]] std::vector<std::string> rotation_terms_at_order(int m, int p_r);

}  // namespace resolver
