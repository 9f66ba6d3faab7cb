// One parameter of an effect as data (ParamInfo), and the compile-time lookup of a
// parameter by name in an effect's list. Kept apart from effect.h so an effect's
// header can expose its list (and the typed access generated from it, param_set.h)
// without pulling in the whole Effect interface.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

namespace resolver {

/// How the fit parameterises a nonlinear parameter internally.
enum class FitScale : std::uint8_t {
  kLinear,         ///< the value itself
  kInverseSquare,  ///< 1 / value^2 (tracking_loop omega_n: 0 = ideal converter is 1/omega_n^2 = 0)
};

/// Two parameters that form an amplitude and a phase (eccentricity e, phase): the
/// forward model and every output use them, the signature's two columns are the
/// derivatives with respect to the Cartesian pair x = amplitude cos(phase),
/// y = amplitude sin(phase), which the fit solves for (a phase is not identifiable
/// at amplitude 0).
enum class Polar : std::uint8_t { kNone, kAmplitude, kPhase };

/// One parameter of an effect, listed once: its name, unit, description and range
/// are written here and nowhere else (param_set.h generates the typed access).
struct ParamInfo {
  std::string_view name;
  std::string_view unit;         ///< e.g. "[rad]", "[1]", "[s]"
  std::string_view description;  ///< one line
  double min = 0.0;              ///< smallest accepted value (inclusive)
  double max = 0.0;              ///< largest accepted value (inclusive)
  double neutral = 0.0;          ///< the value at which the effect does nothing
  bool integer = false;          ///< must be a whole number
  bool listed = true;            ///< shown in --list-effects (false for the long tail, e.g. k6..k20)
  /// Enters the signals nonlinearly (tracking_loop omega_n, delay d): fitted by
  /// Gauss-Newton / Levenberg-Marquardt with numeric derivatives; the others are
  /// linear coefficients of the effect's signature columns.
  bool nonlinear = false;
  FitScale scale = FitScale::kLinear;  ///< nonlinear parameters only
  Polar polar = Polar::kNone;
  /// Part of the effect when a model names it without a parameter list (e.g.
  /// "harmonics" fits k3; "harmonics(k5,k3_opp)" chooses others).
  bool default_fit = true;
};

/// The parameter values of one effect, in the order of its params().
using Values = std::span<const double>;

/// The index of parameter `name` in an effect's ParamInfo list, at compile time:
/// a name the list lacks does not compile. ParamKey (param_set.h) is built on it;
/// effects read their values through ParamSet, not through indices.
template <std::size_t N>
consteval std::size_t param_index(const std::array<ParamInfo, N>& params, std::string_view name) {
  for (std::size_t i = 0; i < N; ++i) {
    if (params[i].name == name) return i;
  }
  throw "param_index: the effect has no parameter of this name";  // not a constant expression: fails to compile
}

}  // namespace resolver
