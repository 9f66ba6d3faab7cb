// Effect: imperfect quadrature between the two resolver windings.
//
// Cause: the cos winding is not mounted exactly pi/2 from the sin winding.
// Forward model (Hanselman eq. 6): the fundamental of the cos channel is
// cos(theta + beta); the sin channel is sin(theta).
// Signature, eps = theta - phi (docs/ARCHITECTURE.md §3, Hanselman's definition of eps):
//   eps ~= -(beta/2) (1 - cos 2theta)
// i.e. the OPPOSITE sign of Hanselman eq. 7 as printed. Derivation: the converter
// settles at tan(phi) = sin(theta) / cos(theta + beta)
//   ~= tan(theta) (1 + beta tan(theta))  =>  phi ~= theta + beta sin^2(theta),
// so phi leads theta by beta sin^2(theta) = (beta/2)(1 - cos 2theta). The unit
// test QuadratureSignMatchesExactModel checks this sign against the exact model.
// The error has a DC part -beta/2 (a constant angle offset) plus a 2theta part,
// and the omitted terms are O(beta^2).
#pragma once

#include <array>

#include "daemon/core/effects/param_set.h"
#include "daemon/core/effects/sin_cos.h"

namespace resolver {

/// The effect's parameters, listed once (param_set.h).
inline constexpr std::array kQuadratureParams{
    ParamInfo{.name = "beta", .unit = "[rad]", .description = "misalignment of the cos winding", .min = -0.5,
              .max = 0.5},
};
using QuadratureParams = ParamSet<kQuadratureParams>;

/// Forward model: fundamental envelopes {sin(theta), cos(theta + beta)} at resolver angle theta [rad].
[[nodiscard]] SinCos quadrature_fundamental(const QuadratureParams& p, double theta);

/// Small-beta position error eps = theta - phi [rad] = -(beta/2)(1 - cos 2theta)
/// (Hanselman eq. 7 with the sign checked against the exact model, see above).
[[nodiscard]] double quadrature_error(const QuadratureParams& p, double theta);

/// The registry unit of this effect (registry.h).
class Effect;
[[nodiscard]] const Effect& quadrature_effect();

}  // namespace resolver
