#include "daemon/core/effects/dead_time.h"

#include <array>
#include <cmath>
#include <numbers>

#include "daemon/core/effects/effect.h"

#include "daemon/core/angles.h"

namespace resolver {

namespace {
/// The distortion of one phase whose fundamental has phase psi [rad] and peak magnitude [A].
double phase_distortion(double k, double magnitude, double psi) {
  return k * magnitude * (std::sin(7.0 * psi) - std::sin(5.0 * psi));
}
}  // namespace

PhaseCurrents apply_dead_time(const DeadTimeParams& p, const PhaseCurrents& fundamental) {
  if (!p.active()) return fundamental;
  // Clarke (docs/ARCHITECTURE.md section 3) gives the fundamental's vector |I| e^{j psi}; phase x has psi_x = psi - x 2pi/3.
  const double alpha = fundamental.a;
  const double beta = (fundamental.b - fundamental.c) / std::numbers::sqrt3;
  const double magnitude = std::hypot(alpha, beta);
  if (magnitude == 0.0) return fundamental;
  const double psi = std::atan2(beta, alpha);
  const double k = dead_time_k_dt(p);
  constexpr double kThird = kTwoPi / 3.0;
  return {fundamental.a + phase_distortion(k, magnitude, psi),
          fundamental.b + phase_distortion(k, magnitude, psi - kThird),
          fundamental.c + phase_distortion(k, magnitude, psi + kThird)};
}

DqCurrents dead_time_dq_error(const DeadTimeParams& p, double i_d, double i_q, double theta_e) {
  if (i_d == 0.0 && i_q == 0.0) return {};
  const double delta = std::atan2(i_q, i_d);
  const double ripple = 2.0 * dead_time_k_dt(p) * std::cos(6.0 * (theta_e + delta));
  return {ripple * i_q, -ripple * i_d};
}

DqCurrents dead_time_ripple_6x(const DeadTimeParams& p, double i_d, double i_q) {
  return {2.0 * dead_time_k_dt(p) * std::abs(i_q), 2.0 * dead_time_k_dt(p) * std::abs(i_d)};
}

}  // namespace resolver

// ---- registry unit ------------------------------------------------------------
namespace resolver {
namespace {

class DeadTimeEffect final : public BasicEffect {
 public:
  DeadTimeEffect()
      : BasicEffect({"dead_time",
                     "signature model: 5th/7th current harmonics k_dt |I|, dq ripple at 6x theta_e (2 k_dt i_q on i_d)",
                     "docs/ARCHITECTURE.md section 7; dead_time.h",
                     "inverter dead time: 5th and 7th harmonics of the phase currents, i.e. a 6x theta_e ripple on i_d "
                     "and i_q perpendicular to the current vector"},
                    kDeadTimeParams, EffectStage::kCurrents) {}
  [[nodiscard]] HarmonicOrders orders(std::span<const int> /*p*/) const override { return {.theta_e = 6}; }
  [[nodiscard]] bool needs_reference() const override { return true; }
  void currents(Values v, CurrentStage stage, double /*theta_e*/, PhaseCurrents& i) const override {
    if (stage == CurrentStage::kInverter) i = apply_dead_time(DeadTimeParams(v), i);
  }
  void signature(const SignatureRow& row, const AngleBasis& /*b*/, Values /*v*/, SignatureColumns& out) const override {
    const DqCurrents a = dead_time_dq_error({{"t_d", 1.0}}, row.i_d0, row.i_q0, row.theta_e);  // per second of t_d
    out.col(DeadTimeParams::index("t_d")) = SignalValues{.d = a.d, .q = a.q};
  }
};

}  // namespace

const Effect& dead_time_effect() {
  static const DeadTimeEffect effect;
  return effect;
}

}  // namespace resolver
