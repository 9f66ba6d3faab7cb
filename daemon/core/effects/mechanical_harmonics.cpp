#include "daemon/core/effects/mechanical_harmonics.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <string_view>

#include <fmt/format.h>

#include "daemon/core/effects/effect.h"

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

double seen_mech(Values v, double theta_m) {
  double out = theta_m;
  for (std::size_t i = 0; i + 1 < v.size(); i += 2) {
    if (v[i] == 0.0 && v[i + 1] == 0.0) continue;
    const double n = static_cast<double>(i / 2 + 1);
    out += v[i] * std::sin(n * theta_m) + v[i + 1] * std::cos(n * theta_m);
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
    for (int p : params) top = std::max(top, p / 2 + 1);
    return {.theta_m = top};
  }
  [[nodiscard]] bool needs_reference() const override { return true; }
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
    double sum = 0.0;
    for (std::size_t i = 0; i < v.size(); ++i) sum += static_cast<double>(i / 2 + 1) * std::abs(v[i]);
    if (!(sum < 1.0)) {
      throw std::invalid_argument(
          "mechanical_harmonics: sum of n (|a_n| + |b_n|) must be < 1 so the resolver keeps turning one way");
    }
  }
  [[nodiscard]] double seen_mech_angle(Values v, double theta_m, double /*omega_m*/, MotionState& /*state*/,
                                       bool /*commit*/) const override {
    return seen_mech(v, theta_m);
  }
  [[nodiscard]] bool shapes_basis() const override { return true; }
  void configure_basis(const SignatureRow& row, Values v, BasisTransform& t) const override {
    t.shift += static_cast<double>(row.p_r) * (seen_mech(v, row.theta_m) - row.theta_m);
  }
  void signature(const SignatureRow& row, const AngleBasis& b, Values /*v*/, SignatureColumns& out) const override {
    const double pr = row.p_r;
    for (int n = 1; n <= kMaxMechanicalOrder; ++n) {
      const auto i = static_cast<std::size_t>(2 * (n - 1));
      out.col(i) = shift_column(-pr * b.rd_mech_sin(n), pr * b.env_mech_sin(n));
      out.col(i + 1) = shift_column(-pr * b.rd_mech_cos(n), pr * b.env_mech_cos(n));
    }
  }
};

}  // namespace

const Effect& mechanical_harmonics_effect() {
  static const MechanicalHarmonicsEffect effect;
  return effect;
}

}  // namespace resolver
