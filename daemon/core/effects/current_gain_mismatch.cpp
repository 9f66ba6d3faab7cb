#include "daemon/core/effects/current_gain_mismatch.h"

#include <array>
#include <cmath>
#include <numbers>

#include "daemon/core/effects/effect.h"

namespace resolver {

PhaseCurrents apply_current_gain_mismatch(const CurrentGainMismatchParams& p, const PhaseCurrents& in) {
  return {(1.0 + p["gain_a"]) * in.a, (1.0 + p["gain_b"]) * in.b, in.c};
}

DqCurrents current_gain_mismatch_dq_error(const CurrentGainMismatchParams& p, double i_d, double i_q,
                                          double theta_e) {
  // The Clarke error of the extra a and b parts, then Park (docs/ARCHITECTURE.md section 3).
  const PhaseCurrents i = ideal_phase_currents(i_d, i_q, theta_e);
  const double d_alpha = p["gain_a"] * i.a;
  const double d_beta = p["gain_b"] * i.b / std::numbers::sqrt3;
  const double ce = std::cos(theta_e);
  const double se = std::sin(theta_e);
  return {d_alpha * ce + d_beta * se, -d_alpha * se + d_beta * ce};
}

namespace {

// The DC part of the dq error at operating current `i`: the error has only a DC and a
// 2x theta_e part (current_gain_mismatch.h), and the 2x part is opposite at theta_e and
// theta_e + pi/2, so their mean is the DC exactly.
DqCurrents dc_error(const CurrentGainMismatchParams& p, DqCurrents i) {
  const DqCurrents a = current_gain_mismatch_dq_error(p, i.d, i.q, 0.0);
  const DqCurrents b = current_gain_mismatch_dq_error(p, i.d, i.q, 0.5 * std::numbers::pi);
  return {0.5 * (a.d + b.d), 0.5 * (a.q + b.q)};
}

}  // namespace

DqCurrents current_gain_mismatch_operating_point(const CurrentGainMismatchParams& p, DqCurrents measured) {
  // (1 + C) I = measured, C's columns the DC error of unit d and q currents. The gains'
  // range (|gain| <= 0.5) keeps 1 + C far from singular.
  const DqCurrents cd = dc_error(p, {.d = 1.0, .q = 0.0});
  const DqCurrents cq = dc_error(p, {.d = 0.0, .q = 1.0});
  const double m11 = 1.0 + cd.d, m12 = cq.d, m21 = cd.q, m22 = 1.0 + cq.q;
  const double det = m11 * m22 - m12 * m21;
  return {(m22 * measured.d - m12 * measured.q) / det, (m11 * measured.q - m21 * measured.d) / det};
}

double current_gain_mismatch_ripple_2x(const CurrentGainMismatchParams& p, double i_d, double i_q) {
  const double u = p["gain_a"] - 0.5 * p["gain_b"];
  return 0.5 * std::hypot(i_d, i_q) * std::sqrt(u * u + p["gain_b"] * p["gain_b"] / 12.0);
}

PhaseCurrents compensate_current_gain_mismatch(const CurrentGainMismatchParams& p, const PhaseCurrents& measured) {
  return {measured.a / (1.0 + p["gain_a"]), measured.b / (1.0 + p["gain_b"]), measured.c};
}

}  // namespace resolver

// ---- registry unit ------------------------------------------------------------
namespace resolver {
namespace {

class CurrentGainMismatchEffect final : public BasicEffect {
 public:
  CurrentGainMismatchEffect()
      : BasicEffect({"current_gain_mismatch",
                     "i_a (1+gain_a), i_b (1+gain_b): dq ripple at 2x theta_e of amplitude |I|/2 sqrt((gain_a - "
                     "gain_b/2)^2 + gain_b^2/12)",
                     "docs/ARCHITECTURE.md section 7; current_gain_mismatch.h",
                     "the phase current sensors differ in gain: i_d and i_q ripple at 2x theta_e proportional to the "
                     "current, while the resolver signals are clean (so it is not the resolver's amplitude imbalance)"},
                    kCurrentGainMismatchParams, EffectStage::kCurrents) {}
  [[nodiscard]] HarmonicOrders orders(std::span<const int> /*p*/) const override { return {.theta_e = 2}; }
  [[nodiscard]] bool needs_reference() const override { return true; }
  void currents(Values v, CurrentStage stage, double /*theta_e*/, PhaseCurrents& i) const override {
    if (stage == CurrentStage::kSensorGain) i = apply_current_gain_mismatch(CurrentGainMismatchParams(v), i);
  }
  // The error at the machine's current, solved from the measured operating point
  // (row.i_d0, row.i_q0) at these gains (current_gain_mismatch.h): exact at any magnitude.
  // Its DC part is the d and q constants' too; the fit's nuisances take it.
  [[nodiscard]] bool linear_in_params() const override { return false; }
  void contribution(const SignatureRow& row, const AngleBasis& /*b*/, Values v, SignalValues& out) const override {
    const CurrentGainMismatchParams p(v);
    const DqCurrents i = current_gain_mismatch_operating_point(p, {.d = row.i_d0, .q = row.i_q0});
    const DqCurrents e = current_gain_mismatch_dq_error(p, i.d, i.q, row.theta_e);
    out.d += e.d;
    out.q += e.q;
  }
  // The contribution's derivatives: with E(g, I) linear in both the gains g and the current
  // I, and I = (1 + C(g))^-1 I_m, dE/dg_k = E_k(I) + E(g, dI/dg_k) where
  // dI/dg_k = -(1 + C(g))^-1 C_k I (C_k: the DC error of gain k alone). At zero gains (a
  // candidate's columns) this is E_k(I_m), the first-order column.
  void signature(const SignatureRow& row, const AngleBasis& /*b*/, Values v, SignatureColumns& out) const override {
    const CurrentGainMismatchParams p(v);
    const DqCurrents i = current_gain_mismatch_operating_point(p, {.d = row.i_d0, .q = row.i_q0});
    const auto column = [&](const CurrentGainMismatchParams& unit) {
      const DqCurrents own = current_gain_mismatch_dq_error(unit, i.d, i.q, row.theta_e);
      const DqCurrents dc = dc_error(unit, i);
      const DqCurrents di = current_gain_mismatch_operating_point(p, {.d = -dc.d, .q = -dc.q});
      const DqCurrents through = current_gain_mismatch_dq_error(p, di.d, di.q, row.theta_e);
      return SignalValues{.d = own.d + through.d, .q = own.q + through.q};
    };
    out.col(CurrentGainMismatchParams::index("gain_a")) = column({{"gain_a", 1.0}, {"gain_b", 0.0}});
    out.col(CurrentGainMismatchParams::index("gain_b")) = column({{"gain_a", 0.0}, {"gain_b", 1.0}});
  }
};

}  // namespace

const Effect& current_gain_mismatch_effect() {
  static const CurrentGainMismatchEffect effect;
  return effect;
}

}  // namespace resolver
