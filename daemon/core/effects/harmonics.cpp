#include "daemon/core/effects/harmonics.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include <fmt/format.h>

#include "daemon/core/effects/effect.h"
#include "daemon/core/effects/first_order_aliases.h"

namespace resolver {

SinCos harmonics_part(const HarmonicsParams& p, double theta) {
  SinCos out{p["k0"], p["k0"]};
  for (int n = 2; n <= kHarmonicsMaxOrder; ++n) {
    const HarmonicKeys& k = harmonic_keys(n);
    const double kn = p[k.same], ko = p[k.opp], qn = p[k.same_q], qo = p[k.opp_q];
    if (kn == 0.0 && ko == 0.0 && qn == 0.0 && qo == 0.0) continue;
    const double nt = static_cast<double>(n) * theta;
    const double sn = std::sin(nt), cn = std::cos(nt);
    out.s += (kn + ko) * sn + (qn + qo) * cn;
    out.c += (kn - ko) * cn - (qn - qo) * sn;
  }
  return out;
}

double harmonics_error(const HarmonicsParams& p, double theta) {
  double eps = -std::numbers::sqrt2 * p["k0"] * std::cos(theta + 0.25 * std::numbers::pi);
  for (int n = 2; n <= kHarmonicsMaxOrder; ++n) {
    const HarmonicKeys& k = harmonic_keys(n);
    const double kn = p[k.same];
    const double ko = p[k.opp];
    if (kn != 0.0) eps -= kn * std::sin(static_cast<double>(n - 1) * theta);
    if (ko != 0.0) eps -= ko * std::sin(static_cast<double>(n + 1) * theta);
    const double qn = p[k.same_q];
    const double qo = p[k.opp_q];
    if (qn != 0.0) eps -= qn * std::cos(static_cast<double>(n - 1) * theta);
    if (qo != 0.0) eps -= qo * std::cos(static_cast<double>(n + 1) * theta);
  }
  return eps;
}

// ---- registry unit ------------------------------------------------------------
namespace {

class HarmonicsEffect final : public BasicEffect {
 public:
  HarmonicsEffect()
      : BasicEffect({"harmonics",
                     "K_0 + K_n {sin, cos}(n theta) on the channels, same sign (k2..k20) or opposite sign "
                     "(k2_opp..k20_opp); eps ~ -sqrt2 K_0 cos(theta+pi/4) - K_n sin((n-1)theta) - K_n_opp "
                     "sin((n+1)theta)",
                     "Hanselman eq. 8-9; harmonics.h",
                     "harmonics of the windings: an error harmonic of the angle that the sin/cos envelopes show "
                     "at another order (K_n at n theta lands on (n-1) theta, K_n_opp on (n+1) theta; Hanselman eq. "
                     "8-9)"},
                    kHarmonicsParams, EffectStage::kWindings) {}
  [[nodiscard]] HarmonicOrders orders(std::span<const int> params) const override {
    // k0: 1 theta; k_n: (n - 1) theta in the angle, n theta in the envelopes; k_n_opp: (n + 1) theta.
    int top = 0;
    for (int p : params) {
      const auto i = static_cast<std::size_t>(p);
      if (i == HarmonicsParams::index("k0")) top = std::max(top, 1);
      for (int n = 2; n <= kHarmonicsMaxOrder; ++n) {
        const HarmonicKeys& k = harmonic_keys(n);
        if (i == k.same.index() || i == k.same_q.index()) top = std::max(top, n);
        if (i == k.opp.index() || i == k.opp_q.index()) top = std::max(top, n + 1);
      }
    }
    return {.theta = top};
  }
  // K_n lands on e^{i n theta} of the envelopes, K_n_opp on e^{-i n theta}: a rotation of
  // the seen angle by (n - 1) theta, resp. (n + 1) theta, does too (first_order_aliases.h).
  [[nodiscard]] std::vector<std::string> first_order_aliases(std::span<const int> params, int p_r) const override {
    std::vector<std::string> out;
    for (int p : params) {
      const auto i = static_cast<std::size_t>(p);
      for (int n = 2; n <= kHarmonicsMaxOrder; ++n) {
        const HarmonicKeys& k = harmonic_keys(n);
        const bool same = i == k.same.index() || i == k.same_q.index();
        const bool opp = i == k.opp.index() || i == k.opp_q.index();
        if (!same && !opp) continue;
        for (std::string& r : rotation_terms_at_order(same ? n - 1 : n + 1, p_r)) {
          if (std::find(out.begin(), out.end(), r) == out.end()) out.push_back(std::move(r));
        }
      }
    }
    return out;
  }
  // A residual at order m of theta is K_{m+1} (same sign) or K_{m-1} opposite
  // (m >= 3), K_0 / K_2 at m = 1 (Hanselman eq. 8-9). Each order alone (in phase
  // with the fundamental, as Hanselman's K_n) and with its quadrature part (a
  // harmonic with its own phase, as measured): the BIC and the simpler-first rule
  // name the pair only where the phase is in the data. A smooth periodic error
  // over many orders (a saturation pattern) as one family (issue 21).
  [[nodiscard]] std::optional<std::vector<CandidateParams>> residual_candidates(const ResidualSpectrum& residual,
                                                                                bool families) const override {
    using Angle = ResidualSpectrum::Angle;
    std::vector<CandidateParams> out;
    for (int m : residual.strongest(Angle::kResolver, 1)) {
      std::vector<std::string> names;
      if (m == 1) names = {"k2", "k0"};
      else names = {fmt::format("k{}", m + 1), m - 1 >= 2 ? fmt::format("k{}_opp", m - 1) : ""};
      for (const std::string& k : names) {
        if (k.empty()) continue;
        out.push_back({.groups = {{k}}});
        if (families && k != "k0") out.push_back({.groups = {{k, k + "_q"}}});
      }
    }
    if (families) {
      CandidateParams family{.groups = {}, .family = true};
      for (int m : residual.significant(Angle::kResolver, 2, kHarmonicsMaxOrder - 1)) {
        family.groups.push_back({fmt::format("k{}", m + 1), fmt::format("k{}_q", m + 1)});
      }
      out.push_back(std::move(family));
    }
    return out;
  }
  [[nodiscard]] bool envelope_only() const override { return true; }
  void windings(Values v, WindingStage stage, double theta, SinCos& env) const override {
    if (stage != WindingStage::kAdditive) return;
    const SinCos h = harmonics_part(HarmonicsParams(v), theta);
    env.s += h.s;
    env.c += h.c;
  }
  // Each column is exact: the envelopes are linear in the K's; the R/D angle's
  // error is sin(theta) dc - cos(theta) ds to first order (harmonics.h).
  void signature(const SignatureRow& /*row*/, const AngleBasis& b, Values /*v*/,
                 SignatureColumns& out) const override {
    out.col(HarmonicsParams::index("k0")) = envelope_column(b, b.rd_sin(1) - b.rd_cos(1), 1.0, 1.0);
    for (int n = 2; n <= kHarmonicsMaxOrder; ++n) {
      const HarmonicKeys& k = harmonic_keys(n);
      out.col(k.same.index()) = envelope_column(b, -b.rd_sin(n - 1), b.env_sin(n), b.env_cos(n));
      out.col(k.opp.index()) = envelope_column(b, -b.rd_sin(n + 1), b.env_sin(n), -b.env_cos(n));
      out.col(k.same_q.index()) = envelope_column(b, -b.rd_cos(n - 1), b.env_cos(n), -b.env_sin(n));
      out.col(k.opp_q.index()) = envelope_column(b, -b.rd_cos(n + 1), b.env_cos(n), b.env_sin(n));
    }
  }
};

}  // namespace

const Effect& harmonics_effect() {
  static const HarmonicsEffect effect;
  return effect;
}

}  // namespace resolver
