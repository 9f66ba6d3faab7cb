#include "daemon/core/effects/harmonics.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include <fmt/format.h>

#include "daemon/core/effects/effect.h"

namespace resolver {

bool Harmonics::active() const {
  if (k0 != 0.0) return true;
  for (std::size_t n = 0; n < k.size(); ++n) {
    if (k[n] != 0.0 || k_opp[n] != 0.0 || k_q[n] != 0.0 || k_opp_q[n] != 0.0) return true;
  }
  return false;
}

SinCos harmonics_part(const Harmonics& p, double theta) {
  SinCos out{p.k0, p.k0};
  for (int n = 2; n <= Harmonics::kMaxOrder; ++n) {
    const auto i = static_cast<std::size_t>(n);
    const double kn = p.k[i], ko = p.k_opp[i], qn = p.k_q[i], qo = p.k_opp_q[i];
    if (kn == 0.0 && ko == 0.0 && qn == 0.0 && qo == 0.0) continue;
    const double nt = static_cast<double>(n) * theta;
    const double sn = std::sin(nt), cn = std::cos(nt);
    out.s += (kn + ko) * sn + (qn + qo) * cn;
    out.c += (kn - ko) * cn - (qn - qo) * sn;
  }
  return out;
}

double harmonics_error(const Harmonics& p, double theta) {
  double eps = -std::numbers::sqrt2 * p.k0 * std::cos(theta + 0.25 * std::numbers::pi);
  for (int n = 2; n <= Harmonics::kMaxOrder; ++n) {
    const double kn = p.k[static_cast<std::size_t>(n)];
    const double ko = p.k_opp[static_cast<std::size_t>(n)];
    if (kn != 0.0) eps -= kn * std::sin(static_cast<double>(n - 1) * theta);
    if (ko != 0.0) eps -= ko * std::sin(static_cast<double>(n + 1) * theta);
    const double qn = p.k_q[static_cast<std::size_t>(n)];
    const double qo = p.k_opp_q[static_cast<std::size_t>(n)];
    if (qn != 0.0) eps -= qn * std::cos(static_cast<double>(n - 1) * theta);
    if (qo != 0.0) eps -= qo * std::cos(static_cast<double>(n + 1) * theta);
  }
  return eps;
}

// ---- registry unit ------------------------------------------------------------
namespace {

constexpr int kOrders = Harmonics::kMaxOrder - 1;  // n = 2..kMaxOrder
constexpr std::string_view kUnit = "[fraction of fundamental]";
constexpr std::string_view kSame = "inductance harmonic K_n, same sign on both windings (Hanselman eq. 8)";
constexpr std::string_view kOpp = "harmonic of opposite sign on the windings (odd nonlinearity)";
constexpr std::string_view kSameQ = "quadrature part of K_n (its phase: K_n sin(n theta + phi))";
constexpr std::string_view kOppQ = "quadrature part of the opposite-sign K_n";
constexpr std::array<std::string_view, kOrders> kSameNames{"k2",  "k3",  "k4",  "k5",  "k6",  "k7",  "k8",
                                                           "k9",  "k10", "k11", "k12", "k13", "k14", "k15",
                                                           "k16", "k17", "k18", "k19", "k20"};
constexpr std::array<std::string_view, kOrders> kOppNames{
    "k2_opp",  "k3_opp",  "k4_opp",  "k5_opp",  "k6_opp",  "k7_opp",  "k8_opp",  "k9_opp",  "k10_opp", "k11_opp",
    "k12_opp", "k13_opp", "k14_opp", "k15_opp", "k16_opp", "k17_opp", "k18_opp", "k19_opp", "k20_opp"};
constexpr std::array<std::string_view, kOrders> kSameQNames{
    "k2_q",  "k3_q",  "k4_q",  "k5_q",  "k6_q",  "k7_q",  "k8_q",  "k9_q",  "k10_q", "k11_q",
    "k12_q", "k13_q", "k14_q", "k15_q", "k16_q", "k17_q", "k18_q", "k19_q", "k20_q"};
constexpr std::array<std::string_view, kOrders> kOppQNames{
    "k2_opp_q",  "k3_opp_q",  "k4_opp_q",  "k5_opp_q",  "k6_opp_q",  "k7_opp_q",  "k8_opp_q",
    "k9_opp_q",  "k10_opp_q", "k11_opp_q", "k12_opp_q", "k13_opp_q", "k14_opp_q", "k15_opp_q",
    "k16_opp_q", "k17_opp_q", "k18_opp_q", "k19_opp_q", "k20_opp_q"};
/// Where each group of parameters starts (parameter order below).
constexpr int kFirstSame = 1, kFirstOpp = 1 + kOrders, kFirstSameQ = 1 + 2 * kOrders, kFirstOppQ = 1 + 3 * kOrders;
constexpr int kParamCount = 1 + 4 * kOrders;

/// Parameter order: k0, k2..k20, k2_opp..k20_opp, k2_q..k20_q, k2_opp_q..k20_opp_q.
/// Listed: the orders a bench meets most (k0..k5, k3_opp, k2_q..k5_q); the model
/// names k3 when it names only "harmonics".
constexpr std::array<ParamInfo, kParamCount> make_params() {
  std::array<ParamInfo, kParamCount> out{};
  out[0] = ParamInfo{.name = "k0", .unit = kUnit, .description = "inductive DC component K_0 on both channels",
                     .min = -0.5, .max = 0.5, .default_fit = false};
  for (int i = 0; i < kOrders; ++i) {
    const int n = i + 2;
    out[static_cast<std::size_t>(1 + i)] = ParamInfo{.name = kSameNames[static_cast<std::size_t>(i)], .unit = kUnit,
                                                     .description = kSame, .min = -0.5, .max = 0.5,
                                                     .listed = n <= 5, .default_fit = n == 3};
    out[static_cast<std::size_t>(1 + kOrders + i)] =
        ParamInfo{.name = kOppNames[static_cast<std::size_t>(i)], .unit = kUnit, .description = kOpp,
                  .min = -0.5, .max = 0.5, .listed = n == 3, .default_fit = false};
    out[static_cast<std::size_t>(kFirstSameQ + i)] =
        ParamInfo{.name = kSameQNames[static_cast<std::size_t>(i)], .unit = kUnit, .description = kSameQ,
                  .min = -0.5, .max = 0.5, .listed = n <= 5, .default_fit = false};
    out[static_cast<std::size_t>(kFirstOppQ + i)] =
        ParamInfo{.name = kOppQNames[static_cast<std::size_t>(i)], .unit = kUnit, .description = kOppQ,
                  .min = -0.5, .max = 0.5, .listed = false, .default_fit = false};
  }
  return out;
}
constexpr auto kParams = make_params();
constexpr std::size_t kK0 = param_index(kParams, "k0");

Harmonics from_values(Values v) {
  Harmonics h;
  h.k0 = v[kK0];
  for (int i = 0; i < kOrders; ++i) {
    const auto n = static_cast<std::size_t>(i + 2);
    h.k[n] = v[static_cast<std::size_t>(kFirstSame + i)];
    h.k_opp[n] = v[static_cast<std::size_t>(kFirstOpp + i)];
    h.k_q[n] = v[static_cast<std::size_t>(kFirstSameQ + i)];
    h.k_opp_q[n] = v[static_cast<std::size_t>(kFirstOppQ + i)];
  }
  return h;
}

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
                    kParams, EffectStage::kWindings) {}
  [[nodiscard]] HarmonicOrders orders(std::span<const int> params) const override {
    // k0: 1 theta; k_n: (n - 1) theta in the angle, n theta in the envelopes; k_n_opp: (n + 1) theta.
    int top = 0;
    for (int p : params) {
      if (p == 0) {
        top = std::max(top, 1);
        continue;
      }
      const int group = (p - 1) / kOrders;  // 0 same, 1 opposite, 2 same q, 3 opposite q
      const int n = (p - 1) % kOrders + 2;
      top = std::max(top, group % 2 == 0 ? n : n + 1);
    }
    return {.theta = top};
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
      for (int m : residual.significant(Angle::kResolver, 2, Harmonics::kMaxOrder - 1)) {
        family.groups.push_back({fmt::format("k{}", m + 1), fmt::format("k{}_q", m + 1)});
      }
      out.push_back(std::move(family));
    }
    return out;
  }
  [[nodiscard]] bool envelope_only() const override { return true; }
  void windings(Values v, WindingStage stage, double theta, SinCos& env) const override {
    if (stage != WindingStage::kAdditive) return;
    const SinCos h = harmonics_part(from_values(v), theta);
    env.s += h.s;
    env.c += h.c;
  }
  // Each column is exact: the envelopes are linear in the K's; the R/D angle's
  // error is sin(theta) dc - cos(theta) ds to first order (harmonics.h).
  void signature(const SignatureRow& /*row*/, const AngleBasis& b, Values /*v*/,
                 SignatureColumns& out) const override {
    out.col(0) = envelope_column(b, b.rd_sin(1) - b.rd_cos(1), 1.0, 1.0);
    for (int i = 0; i < kOrders; ++i) {
      const int n = i + 2;
      out.col(static_cast<std::size_t>(1 + i)) =
          envelope_column(b, -b.rd_sin(n - 1), b.env_sin(n), b.env_cos(n));
      out.col(static_cast<std::size_t>(1 + kOrders + i)) =
          envelope_column(b, -b.rd_sin(n + 1), b.env_sin(n), -b.env_cos(n));
      out.col(static_cast<std::size_t>(kFirstSameQ + i)) =
          envelope_column(b, -b.rd_cos(n - 1), b.env_cos(n), -b.env_sin(n));
      out.col(static_cast<std::size_t>(kFirstOppQ + i)) =
          envelope_column(b, -b.rd_cos(n + 1), b.env_cos(n), b.env_sin(n));
    }
  }
};

}  // namespace

const Effect& harmonics_effect() {
  static const HarmonicsEffect effect;
  return effect;
}

}  // namespace resolver
