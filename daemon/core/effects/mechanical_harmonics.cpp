#include "daemon/core/effects/mechanical_harmonics.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <string_view>
#include <utility>

#include <fmt/format.h>

#include "daemon/core/effects/effect.h"
#include "daemon/core/effects/first_order_aliases.h"
#include "daemon/core/effects/param_set.h"

namespace resolver {
namespace {

constexpr std::array<std::string_view, 2 * kMaxMechanicalOrder> kNames{
    "a1",  "b1",  "a2",  "b2",  "a3",  "b3",  "a4",  "b4",  "a5",  "b5",  "a6",
    "b6",  "a7",  "b7",  "a8",  "b8",  "a9",  "b9",  "a10", "b10", "a11", "b11",
    "a12", "b12", "a13", "b13", "a14", "b14", "a15", "b15", "a16", "b16"};

/// Parameter order a1, b1, a2, b2, ...; a model that names the effect alone fits order 2.
/// Range: the seen angle stays monotone while sum n (|a_n| + |b_n|) < 1 (validate()),
/// so one order alone may reach 0.99 / n (and 0.5 rad at most, as before for n = 1, 2).
constexpr std::array<ParamInfo, 2 * kMaxMechanicalOrder> make_params() {
  std::array<ParamInfo, 2 * kMaxMechanicalOrder> out{};
  for (std::size_t i = 0; i < out.size(); ++i) {
    const int order = static_cast<int>(i / 2) + 1;
    const double limit = std::min(0.5, 0.99 / order);
    out[i] = ParamInfo{.name = kNames[i], .unit = "[rad]",
                       .description = i % 2 == 0 ? "sin(n theta_m) part of the seen-angle error (mechanical rad)"
                                                 : "cos(n theta_m) part of the seen-angle error (mechanical rad)",
                       .min = -limit, .max = limit, .listed = order <= 2, .default_fit = order == 2};
  }
  return out;
}
constexpr auto kParams = make_params();
/// Typed, named access to the values of kParams (param_set.h).
using MechanicalHarmonicsParams = ParamSet<kParams>;

/// The pair (a_n, b_n) of one order n, found by name in the list.
struct OrderKeys {
  MechanicalHarmonicsParams::Key a;
  MechanicalHarmonicsParams::Key b;
};
template <std::size_t... I>
consteval std::array<OrderKeys, sizeof...(I)> make_keys(std::index_sequence<I...> /*orders*/) {
  using Key = MechanicalHarmonicsParams::Key;
  return {OrderKeys{Key(kNames[2 * I]), Key(kNames[2 * I + 1])}...};
}
constexpr auto kOrderKeys = make_keys(std::make_index_sequence<kMaxMechanicalOrder>{});
/// The keys of order n = 1..kMaxMechanicalOrder (not checked).
constexpr const OrderKeys& order_keys(int n) { return kOrderKeys[static_cast<std::size_t>(n - 1)]; }

double seen_mech(const MechanicalHarmonicsParams& p, double theta_m) {
  double out = theta_m;
  for (int order = 1; order <= kMaxMechanicalOrder; ++order) {
    const OrderKeys& k = order_keys(order);
    if (p[k.a] == 0.0 && p[k.b] == 0.0) continue;
    const auto n = static_cast<double>(order);
    out += p[k.a] * std::sin(n * theta_m) + p[k.b] * std::cos(n * theta_m);
  }
  return out;
}

class MechanicalHarmonicsEffect final : public BasicEffect {
 public:
  MechanicalHarmonicsEffect()
      : BasicEffect({"mechanical_harmonics",
                     "resolver sees theta_m + sum a_n sin(n theta_m) + b_n cos(n theta_m): eps at orders n/p_r of "
                     "theta (order 1 = eccentricity, 2 = coupling misalignment)",
                     "mechanical_harmonics.h",
                     "the shaft or coupling makes the resolver see a mechanical harmonic of the angle: a position "
                     "error at a whole order of the mechanical turn, only visible against the reference encoder"},
                    kParams, EffectStage::kMotion) {}
  [[nodiscard]] HarmonicOrders orders(std::span<const int> params) const override {
    int top = 0;
    for (int p : params) {
      for (int n = 1; n <= kMaxMechanicalOrder; ++n) {
        const OrderKeys& k = order_keys(n);
        if (static_cast<std::size_t>(p) == k.a.index() || static_cast<std::size_t>(p) == k.b.index()) {
          top = std::max(top, n);
        }
      }
    }
    return {.theta_m = top};
  }
  [[nodiscard]] bool needs_reference() const override { return true; }
  // An order that is a whole electrical one, m = n / p_r, rotates the envelopes as that
  // order's winding terms do at first order (first_order_aliases.h).
  [[nodiscard]] std::vector<std::string> first_order_aliases(std::span<const int> params, int p_r) const override {
    std::vector<std::string> out;
    for (int n = 1; n <= kMaxMechanicalOrder; ++n) {
      const OrderKeys& k = order_keys(n);
      const bool fitted = std::any_of(params.begin(), params.end(), [&](int p) {
        return static_cast<std::size_t>(p) == k.a.index() || static_cast<std::size_t>(p) == k.b.index();
      });
      if (!fitted || p_r < 1 || n % p_r != 0) continue;
      for (std::string& r : winding_terms_at_order(n / p_r)) {
        if (std::find(out.begin(), out.end(), r) == out.end()) out.push_back(std::move(r));
      }
    }
    return out;
  }
  // An order's (a_n, b_n) pair at the orders the residual shows over the mechanical
  // turn, from 2 (order 1 is eccentricity's, a candidate of its own); offline also
  // every significant order as one family.
  [[nodiscard]] std::optional<std::vector<CandidateParams>> residual_candidates(const ResidualSpectrum& residual,
                                                                                bool families) const override {
    using Angle = ResidualSpectrum::Angle;
    std::vector<CandidateParams> out;
    for (int m : residual.strongest(Angle::kMechanical, 2)) {
      out.push_back({.groups = {{fmt::format("a{}", m), fmt::format("b{}", m)}}});
    }
    if (families) {
      CandidateParams family{.groups = {}, .family = true};
      for (int m : residual.significant(Angle::kMechanical, 2, kMaxMechanicalOrder)) {
        family.groups.push_back({fmt::format("a{}", m), fmt::format("b{}", m)});
      }
      out.push_back(std::move(family));
    }
    return out;
  }
  void validate(Values v) const override {
    const MechanicalHarmonicsParams p(v);
    double sum = 0.0;
    for (int n = 1; n <= kMaxMechanicalOrder; ++n) {
      sum += static_cast<double>(n) * std::abs(p[order_keys(n).a]);
      sum += static_cast<double>(n) * std::abs(p[order_keys(n).b]);
    }
    if (!(sum < 1.0)) {
      throw std::invalid_argument(
          "mechanical_harmonics: sum of n (|a_n| + |b_n|) must be < 1 so the resolver keeps turning one way");
    }
  }
  [[nodiscard]] double seen_mech_angle(Values v, double theta_m, double /*omega_m*/, MotionState& /*state*/,
                                       bool /*commit*/) const override {
    return seen_mech(MechanicalHarmonicsParams(v), theta_m);
  }
  [[nodiscard]] bool shapes_basis() const override { return true; }
  void configure_basis(const SignatureRow& row, Values v, BasisTransform& t) const override {
    t.shift += static_cast<double>(row.p_r) * (seen_mech(MechanicalHarmonicsParams(v), row.theta_m) - row.theta_m);
  }
  void signature(const SignatureRow& row, const AngleBasis& b, Values /*v*/, SignatureColumns& out) const override {
    const double pr = row.p_r;
    for (int n = 1; n <= kMaxMechanicalOrder; ++n) {
      out.col(order_keys(n).a.index()) = shift_column(-pr * b.rd_mech_sin(n), pr * b.env_mech_sin(n));
      out.col(order_keys(n).b.index()) = shift_column(-pr * b.rd_mech_cos(n), pr * b.env_mech_cos(n));
    }
  }
};

}  // namespace

const Effect& mechanical_harmonics_effect() {
  static const MechanicalHarmonicsEffect effect;
  return effect;
}

}  // namespace resolver
