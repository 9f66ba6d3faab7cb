#include "daemon/core/effects/harmonics.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include "daemon/core/effects/effect.h"

namespace resolver {

bool Harmonics::active() const {
  if (k0 != 0.0) return true;
  for (std::size_t n = 0; n < k.size(); ++n) {
    if (k[n] != 0.0 || k_opp[n] != 0.0) return true;
  }
  return false;
}

SinCos harmonics_part(const Harmonics& p, double theta) {
  SinCos out{p.k0, p.k0};
  for (int n = 2; n <= Harmonics::kMaxOrder; ++n) {
    const double kn = p.k[static_cast<std::size_t>(n)];
    const double ko = p.k_opp[static_cast<std::size_t>(n)];
    if (kn == 0.0 && ko == 0.0) continue;
    const double nt = static_cast<double>(n) * theta;
    out.s += (kn + ko) * std::sin(nt);
    out.c += (kn - ko) * std::cos(nt);
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
  }
  return eps;
}

// ---- registry unit ------------------------------------------------------------
namespace {

constexpr int kOrders = Harmonics::kMaxOrder - 1;  // n = 2..kMaxOrder
constexpr std::string_view kUnit = "[fraction of fundamental]";
constexpr std::string_view kSame = "inductance harmonic K_n, same sign on both windings (Hanselman eq. 8)";
constexpr std::string_view kOpp = "harmonic of opposite sign on the windings (odd nonlinearity)";
constexpr std::array<std::string_view, kOrders> kSameNames{"k2",  "k3",  "k4",  "k5",  "k6",  "k7",  "k8",
                                                           "k9",  "k10", "k11", "k12", "k13", "k14", "k15",
                                                           "k16", "k17", "k18", "k19", "k20"};
constexpr std::array<std::string_view, kOrders> kOppNames{
    "k2_opp",  "k3_opp",  "k4_opp",  "k5_opp",  "k6_opp",  "k7_opp",  "k8_opp",  "k9_opp",  "k10_opp", "k11_opp",
    "k12_opp", "k13_opp", "k14_opp", "k15_opp", "k16_opp", "k17_opp", "k18_opp", "k19_opp", "k20_opp"};

/// Parameter order: k0, k2..k20, k2_opp..k20_opp. Listed: the orders a bench
/// meets most (k0..k5, k3_opp); the model names k3 when it names only "harmonics".
constexpr std::array<ParamInfo, 1 + 2 * kOrders> make_params() {
  std::array<ParamInfo, 1 + 2 * kOrders> out{};
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
  }
  return out;
}
constexpr auto kParams = make_params();

Harmonics from_values(Values v) {
  Harmonics h;
  h.k0 = v[0];
  for (int i = 0; i < kOrders; ++i) {
    h.k[static_cast<std::size_t>(i + 2)] = v[static_cast<std::size_t>(1 + i)];
    h.k_opp[static_cast<std::size_t>(i + 2)] = v[static_cast<std::size_t>(1 + kOrders + i)];
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
    for (int p : params) top = std::max(top, p == 0 ? 1 : (p <= kOrders ? p + 1 : p - kOrders + 2));
    return {.theta = top};
  }
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
    }
  }
};

}  // namespace

const Effect& harmonics_effect() {
  static const HarmonicsEffect effect;
  return effect;
}

}  // namespace resolver
