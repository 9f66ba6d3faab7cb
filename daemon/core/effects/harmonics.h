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
#include <cstddef>
#include <string_view>
#include <utility>

#include "daemon/core/effects/param_set.h"
#include "daemon/core/effects/sin_cos.h"

namespace resolver {

/// Highest harmonic order a spec may set (k2 .. k20, k2_opp .. k20_opp).
inline constexpr int kHarmonicsMaxOrder = 20;

namespace harmonics_list {
// How the list below is built: four names per order n = 2..kHarmonicsMaxOrder.
inline constexpr int kOrders = kHarmonicsMaxOrder - 1;
inline constexpr std::string_view kUnit = "[fraction of fundamental]";
inline constexpr std::string_view kSame = "inductance harmonic K_n, same sign on both windings (Hanselman eq. 8)";
inline constexpr std::string_view kOpp = "harmonic of opposite sign on the windings (odd nonlinearity)";
inline constexpr std::string_view kSameQ = "quadrature part of K_n (its phase: K_n sin(n theta + phi))";
inline constexpr std::string_view kOppQ = "quadrature part of the opposite-sign K_n";
inline constexpr std::array<std::string_view, kOrders> kSameNames{"k2",  "k3",  "k4",  "k5",  "k6",  "k7",  "k8",
                                                                  "k9",  "k10", "k11", "k12", "k13", "k14", "k15",
                                                                  "k16", "k17", "k18", "k19", "k20"};
inline constexpr std::array<std::string_view, kOrders> kOppNames{
    "k2_opp",  "k3_opp",  "k4_opp",  "k5_opp",  "k6_opp",  "k7_opp",  "k8_opp",  "k9_opp",  "k10_opp", "k11_opp",
    "k12_opp", "k13_opp", "k14_opp", "k15_opp", "k16_opp", "k17_opp", "k18_opp", "k19_opp", "k20_opp"};
inline constexpr std::array<std::string_view, kOrders> kSameQNames{
    "k2_q",  "k3_q",  "k4_q",  "k5_q",  "k6_q",  "k7_q",  "k8_q",  "k9_q",  "k10_q", "k11_q",
    "k12_q", "k13_q", "k14_q", "k15_q", "k16_q", "k17_q", "k18_q", "k19_q", "k20_q"};
inline constexpr std::array<std::string_view, kOrders> kOppQNames{
    "k2_opp_q",  "k3_opp_q",  "k4_opp_q",  "k5_opp_q",  "k6_opp_q",  "k7_opp_q",  "k8_opp_q",
    "k9_opp_q",  "k10_opp_q", "k11_opp_q", "k12_opp_q", "k13_opp_q", "k14_opp_q", "k15_opp_q",
    "k16_opp_q", "k17_opp_q", "k18_opp_q", "k19_opp_q", "k20_opp_q"};

/// Parameter order: k0, k2..k20, k2_opp..k20_opp, k2_q..k20_q, k2_opp_q..k20_opp_q.
/// Listed: the orders a bench meets most (k0..k5, k3_opp, k2_q..k5_q); the model
/// names k3 when it names only "harmonics".
consteval std::array<ParamInfo, 1 + 4 * kOrders> make_params() {
  std::array<ParamInfo, 1 + 4 * kOrders> out{};
  std::size_t at = 0;
  out[at++] = ParamInfo{.name = "k0", .unit = kUnit, .description = "inductive DC component K_0 on both channels",
                        .min = -0.5, .max = 0.5, .default_fit = false};
  for (std::size_t i = 0; i < kOrders; ++i) {
    const auto n = static_cast<int>(i) + 2;
    out[at++] = ParamInfo{.name = kSameNames[i], .unit = kUnit, .description = kSame, .min = -0.5, .max = 0.5,
                          .listed = n <= 5, .default_fit = n == 3};
  }
  for (std::size_t i = 0; i < kOrders; ++i) {
    out[at++] = ParamInfo{.name = kOppNames[i], .unit = kUnit, .description = kOpp, .min = -0.5, .max = 0.5,
                          .listed = i + 2 == 3, .default_fit = false};
  }
  for (std::size_t i = 0; i < kOrders; ++i) {
    out[at++] = ParamInfo{.name = kSameQNames[i], .unit = kUnit, .description = kSameQ, .min = -0.5, .max = 0.5,
                          .listed = i + 2 <= 5, .default_fit = false};
  }
  for (std::size_t i = 0; i < kOrders; ++i) {
    out[at++] = ParamInfo{.name = kOppQNames[i], .unit = kUnit, .description = kOppQ, .min = -0.5, .max = 0.5,
                          .listed = false, .default_fit = false};
  }
  return out;
}
}  // namespace harmonics_list

/// The effect's parameters, listed once (param_set.h).
inline constexpr std::array kHarmonicsParams = harmonics_list::make_params();
using HarmonicsParams = ParamSet<kHarmonicsParams>;

/// The four parameters of one order n, found by name in the list.
struct HarmonicKeys {
  HarmonicsParams::Key same;    ///< K_n
  HarmonicsParams::Key opp;     ///< K_n_opp
  HarmonicsParams::Key same_q;  ///< K_n_q
  HarmonicsParams::Key opp_q;   ///< K_n_opp_q
};

namespace harmonics_list {
template <std::size_t... I>
consteval std::array<HarmonicKeys, sizeof...(I)> make_keys(std::index_sequence<I...> /*orders*/) {
  using Key = HarmonicsParams::Key;
  return {HarmonicKeys{Key(kSameNames[I]), Key(kOppNames[I]), Key(kSameQNames[I]), Key(kOppQNames[I])}...};
}
inline constexpr auto kKeys = make_keys(std::make_index_sequence<kOrders>{});
}  // namespace harmonics_list

/// The keys of order n = 2..kHarmonicsMaxOrder (not checked).
[[nodiscard]] constexpr const HarmonicKeys& harmonic_keys(int n) {
  return harmonics_list::kKeys[static_cast<std::size_t>(n - 2)];
}

/// Forward model: the harmonic part (K_0 and K_n, n >= 2) of the envelopes at
/// resolver angle theta [rad], to be added to the fundamental.
[[nodiscard]] SinCos harmonics_part(const HarmonicsParams& p, double theta);

/// Small-K position error eps = theta - phi [rad] (Hanselman eq. 9).
[[nodiscard]] double harmonics_error(const HarmonicsParams& p, double theta);

/// The registry unit of this effect (registry.h).
class Effect;
[[nodiscard]] const Effect& harmonics_effect();

}  // namespace resolver
