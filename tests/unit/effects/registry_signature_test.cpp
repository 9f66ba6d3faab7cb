// The generic signature test (issue 12, part 2): for every effect of the registry,
// every parameter and every signal, the effect's signature column (what the fit
// uses) equals the finite-difference derivative of the simulator's forward chain
// (daemon/core/effects/forward_chain.h: what the simulator writes into a log) at
// small parameter values. A sign or scale slip in any effect fails here.
//
// Forward side, per true angle at constant speed:
//   rd    theta_true - phi, phi from the converter: atan2 of its envelopes (ideal),
//         or the type-II loop integrated to steady state (tracking_loop.h) when the
//         chain has one
//   sa    theta_true - atan2 of the DSP's envelopes; sr their radius - 1
//   d, q  the measured currents in the frame of the true theta_e, minus the command
// Model side: the effect's SignatureColumns through AngleBasis (signature.h).
//
// Tolerance: central differences with step h = 1e-6 of the parameter's range
// have a truncation error O(h^2 f''') and rounding ~1e-16 / h relative; both are
// below 1e-7 of the column's size here, so 1e-5 of the largest |column| over the
// angle grid leaves two orders of margin while any slip in sign or scale (an
// error of 100 %) or a missing term of relative size >= 1e-5 fails.
// The d/q signals are compared after removing their mean over the grid: a steady
// dq shift is the operating point, which the fit's nuisance columns absorb
// (mounting_offset has no dq column for that reason).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "daemon/core/angles.h"
#include "daemon/core/effects/chain_values.h"
#include "daemon/core/effects/forward_chain.h"
#include "daemon/core/effects/registry.h"
#include "daemon/core/effects/tracking_loop.h"
#include "daemon/core/estimation/dq_transform.h"

namespace resolver {
namespace {

struct Bench {
  int p_r = 3;
  int p = 4;
  double omega_m = 2.0 * kPi * 200.0 / 60.0;  ///< [rad/s] 200 r/min; negative = backwards
  double i_d_cmd = 1.0, i_q_cmd = 10.0;        ///< [A] (a d part so both dq columns are exercised)
};

constexpr int kGrid = 72;  // angles over one mechanical turn (not a multiple of the orders tested)

double theta_m_at(const Bench& b, double t) { return 0.3 + b.omega_m * t; }
double time_of(const Bench& b, int i) { return (kTwoPi * i / kGrid) / std::abs(b.omega_m); }

/// The forward chain's five signals at grid point i.
SignalValues forward_signals(const ChainValues& values, const Bench& b, int i) {
  ForwardChain chain(values, b.p_r, b.p);
  const double t = time_of(b, i);
  const double theta_true = b.p_r * theta_m_at(b, t);
  auto seen = [&](double tt) { return chain.resolver_angle(theta_m_at(b, tt), b.omega_m, false); };
  const double tr = t - chain.time_shift();
  // Each channel at its own time (windings that drift in time: envelope_drift), as the simulator takes them.
  auto converter_env = [&](double tt) {
    const double a = tt - chain.time_shift();
    const double cos_dt = chain.timing().converter_cos_dt;
    const SinCos at_sin = chain.envelopes(seen(a), tt);
    return SinCos{at_sin.s, chain.envelopes(seen(a + cos_dt), tt + cos_dt).c};
  };
  double phi = 0.0;
  const ConverterSpec conv = chain.converter();
  if (tracking_loop_active(conv.loop)) {
    // Steady state: start converged 40 / (zeta omega_n) earlier (e^-40 of any transient left).
    const double settle = 40.0 / (conv.loop["zeta"] * conv.loop["omega_n"]);
    TrackingLoop loop(conv.loop);
    const double t0 = t - settle;
    const double static0 = static_rd_angle(converter_env(t0));
    const double th0 = b.p_r * theta_m_at(b, t0);
    loop.reset({th0 - wrap_pi(th0 - static0), b.p_r * b.omega_m});
    loop.advance(converter_env, t0, settle);
    phi = loop.state().phi;
  } else {
    phi = static_rd_angle(converter_env(t));
  }
  SignalValues out;
  out.rd = wrap_pi(theta_true - phi);
  const double dsp_cos_dt = chain.timing().dsp_cos_dt;
  const SinCos s_at = chain.envelopes(seen(tr), t);
  const SinCos c_at = chain.envelopes(seen(tr + dsp_cos_dt), t + dsp_cos_dt);
  out.sa = wrap_pi(theta_true - std::atan2(s_at.s, c_at.c));
  out.sr = std::hypot(s_at.s, c_at.c) - 1.0;
  const double theta_e = b.p * theta_m_at(b, t);
  const PhaseCurrents m = chain.measured_currents(chain.machine_currents(b.i_d_cmd, b.i_q_cmd, theta_e), theta_e);
  const ClarkeTransform ab(m.a, m.b, m.c);
  const ParkTransform dq(ab.alpha, ab.beta, theta_e);
  out.d = dq.d - b.i_d_cmd;
  out.q = dq.q - b.i_q_cmd;
  return out;
}

SignatureRow row_at(const Bench& b, int i) {
  const double t = time_of(b, i);
  SignatureRow r;
  r.t = t;
  r.theta_m = theta_m_at(b, t);
  r.theta = b.p_r * r.theta_m;
  r.omega = b.p_r * b.omega_m;
  r.direction = b.omega_m < 0.0 ? -1.0 : 1.0;
  r.theta_e = b.p * r.theta_m;
  r.i_d0 = b.i_d_cmd;
  r.i_q0 = b.i_q_cmd;
  r.p_r = b.p_r;
  r.p = b.p;
  return r;
}

using Series = std::vector<std::vector<double>>;  // [signal][grid point]
constexpr int kSignals = 5;
const char* const kSignalNames[kSignals] = {"rd", "sa", "sr", "d", "q"};

std::vector<double> as_array(const SignalValues& v) { return {v.rd, v.sa, v.sr, v.d, v.q}; }

void compare(const Series& column, const Series& fd, const std::string& what, double rounding) {
  for (int k = 0; k < kSignals; ++k) {
    std::vector<double> a = column[k], f = fd[k];
    if (k >= 3) {  // dq: the operating point absorbs a steady shift
      double ma = 0.0, mf = 0.0;
      for (std::size_t i = 0; i < a.size(); ++i) {
        ma += a[i] / kGrid;
        mf += f[i] / kGrid;
      }
      for (std::size_t i = 0; i < a.size(); ++i) {
        a[i] -= ma;
        f[i] -= mf;
      }
    }
    double scale = 0.0, worst = 0.0;
    for (std::size_t i = 0; i < a.size(); ++i) {
      scale = std::max({scale, std::abs(a[i]), std::abs(f[i])});
      worst = std::max(worst, std::abs(a[i] - f[i]));
    }
    EXPECT_LE(worst, 1e-5 * scale + rounding) << what << ", signal " << kSignalNames[k] << ": column and forward "
                                           << "derivative differ by " << worst << " (largest value " << scale << ")";
  }
}

/// The parameter's finite-difference step and whether the differences are one-sided (neutral at the range's edge).
double step_of(const ParamInfo& p) { return 1e-6 * (p.max - p.min); }

void check_linear_parameter(const Effect& e, std::size_t j, const Bench& b) {
  const ParamInfo& p = e.params()[j];
  const std::string what = std::string(e.name()) + "." + std::string(p.name) +
                           (b.omega_m < 0 ? " backwards" : "") + " p_r=" + std::to_string(b.p_r);
  const double h = step_of(p);
  const bool one_sided = p.neutral - h < p.min;
  // Polar pairs: the columns are the Cartesian pair's (effect.h), so perturb
  // x = amplitude cos(phase) (phase 0) or y (phase pi/2).
  const bool polar = p.polar != Polar::kNone;
  const int amp = polar ? (p.polar == Polar::kAmplitude ? static_cast<int>(j) : static_cast<int>(j) - 1) : -1;
  auto chain_with = [&](double value) {
    ChainValues v;
    if (polar) {
      v.set(e.name(), e.params()[static_cast<std::size_t>(amp)].name, value);
      v.set(e.name(), e.params()[static_cast<std::size_t>(amp) + 1].name, p.polar == Polar::kAmplitude ? 0.0 : kPi / 2);
    } else {
      v.set(e.name(), p.name, value);
    }
    return v;
  };
  const ChainValues plus = chain_with(p.neutral + h);
  const ChainValues minus = chain_with(one_sided ? p.neutral : p.neutral - h);
  const double span = one_sided ? h : 2.0 * h;
  Series column(kSignals), fd(kSignals);
  const ChainValues neutral;
  const Values v0 = neutral.of(e);
  std::vector<SignalValues> storage(e.params().size());
  AngleBasis basis;
  for (int i = 0; i < kGrid; ++i) {
    const SignatureRow r = row_at(b, i);
    basis.set(r, BasisTransform{});
    SignatureColumns cols(storage);
    cols.clear();
    e.signature(r, basis, v0, cols);
    const auto c = as_array(cols.col(j));
    const auto fp = as_array(forward_signals(plus, b, i));
    const auto fm = as_array(forward_signals(minus, b, i));
    for (int k = 0; k < kSignals; ++k) {
      column[k].push_back(c[k]);
      fd[k].push_back((fp[k] - fm[k]) / span);
    }
  }
  // Rounding of the differenced signals: ~50 ulp of the largest signal (the
  // currents, ~10 A) over the step.
  const double rounding = 50.0 * 2.2e-16 * std::max(1.0, std::hypot(b.i_d_cmd, b.i_q_cmd)) / span;
  compare(column, fd, what, rounding);
}

TEST(RegistrySignatures, EveryLinearParameterMatchesTheForwardChainDerivative) {
  int checked = 0;
  for (const Bench& b : {Bench{}, Bench{.p_r = 1, .p = 3}, Bench{.omega_m = -2.0 * kPi * 200.0 / 60.0}}) {
    for (const Effect* e : effect_registry()) {
      if (!e->fittable()) continue;
      for (std::size_t j = 0; j < e->params().size(); ++j) {
        if (e->params()[j].nonlinear) continue;
        check_linear_parameter(*e, j, b);
        ++checked;
      }
    }
  }
  // Every fittable linear parameter of the registry on three benches (86 today);
  // a new effect is covered without editing this test. The bound only guards
  // against the loop silently checking nothing.
  EXPECT_GE(checked, 3 * 80);
}

TEST(RegistrySignatures, EnvelopeOnlyEffectsDoNotChangeInTime) {
  // The fit evaluates the envelope_only() effects jointly as a Fourier series of the
  // angle alone (envelope_spectrum.h): an effect whose windings drift in time
  // (Effect::windings_in_time) must describe itself through signature() instead.
  // Every parameter at 1 % of its range from neutral, the chain at two times.
  int checked = 0;
  for (const Effect* e : effect_registry()) {
    if (!e->envelope_only()) continue;
    for (const ParamInfo& p : e->params()) {
      ChainValues v;
      v.set(e->name(), p.name, p.neutral < p.max ? p.neutral + 0.01 * (p.max - p.neutral) : p.neutral - 0.01 * (p.neutral - p.min));
      const ForwardChain chain(v, 3, 3);
      for (int i = 0; i < kGrid; ++i) {
        const double theta = kTwoPi * (i + 0.37) / kGrid;
        const SinCos a = chain.envelopes(theta, 0.0), b = chain.envelopes(theta, 123.4);
        ASSERT_EQ(a.s, b.s) << e->name() << "." << p.name << " changes in time but is envelope_only()";
        ASSERT_EQ(a.c, b.c) << e->name() << "." << p.name << " changes in time but is envelope_only()";
      }
      ++checked;
    }
  }
  EXPECT_GE(checked, 4) << "amplitude_imbalance, quadrature, offsets and harmonics are envelope_only()";
}

/// The model's prediction of the rd/s/c signals for `values` (all effects), as the fit builds it.
SignalValues model_prediction(const ChainValues& values, const Bench& b, int i) {
  const SignatureRow r = row_at(b, i);
  BasisTransform t;
  for (const Effect* e : effect_registry()) {
    if (values.active(*e)) e->configure_basis(r, values.of(*e), t);
  }
  AngleBasis basis;
  basis.set(r, t);
  SignalValues out;
  for (const Effect* e : effect_registry()) {
    if (!e->fittable() || !values.active(*e)) continue;
    e->contribution(r, basis, values.of(*e), out);
  }
  return out;
}

/// Nonlinear parameters act through the basis on every other effect: compare the
/// model's prediction with the forward chain at finite values, with a 2theta and a
/// 1x mechanical error present so the transform of both kinds of harmonics is
/// exercised. Tolerance: the first-order model omits terms of second order in the
/// small parameters (alpha^2 ~ 4e-6 here); the converter's loop is linear in its
/// error (the omitted cubic term is ~ripple^3 ~ 1e-9 rad).
void check_nonlinear(const std::string& spec, const Bench& b, double tol_rad) {
  ChainValues v;
  v.apply_spec("amplitude_imbalance:alpha=0.002");
  v.apply_spec("mechanical_harmonics:a1=2e-4");
  v.apply_spec(spec);
  double worst = 0.0, worst_s = 0.0;
  for (int i = 0; i < kGrid; ++i) {
    const SignalValues f = forward_signals(v, b, i);
    const SignalValues m = model_prediction(v, b, i);
    worst = std::max(worst, std::abs(f.rd - m.rd));
    worst_s = std::max({worst_s, std::abs(f.sa - m.sa), std::abs(f.sr - m.sr)});
  }
  EXPECT_LE(worst, tol_rad) << spec << ": model rd prediction vs forward chain";
  EXPECT_LE(worst_s, tol_rad) << spec << ": model sin/cos prediction vs forward chain";
}

TEST(RegistrySignatures, NonlinearParametersTransformEveryHarmonicLikeTheForwardChain) {
  // 3000 r/min: the 2theta ripple (1885 rad/s with p_r = 3) is near the loop's
  // omega_n = 3000 rad/s, so |H| = 1.25 and the phase moves ~14 deg: a wrong
  // transform would miss by ~3e-4 rad; the bound 2e-5 is alpha^2 terms (4e-6) with margin.
  const Bench fast{.omega_m = 2.0 * kPi * 3000.0 / 60.0};
  check_nonlinear("tracking_loop:omega_n=3000,zeta=0.7", fast, 2e-5);
  // 2 ms at 200 r/min: omega d = 0.126 rad of offset, and the 2theta ripple shifted by 0.25 rad.
  check_nonlinear("delay:d=2e-3", Bench{}, 2e-5);
  check_nonlinear("delay:d=-1e-3", Bench{.omega_m = -2.0 * kPi * 200.0 / 60.0}, 2e-5);
}

TEST(RegistrySignatures, WithoutTheNonlinearTermsTheBoundWouldFail) {
  // Control for the test above: the same comparison with the delay's harmonic shift
  // left out (the delay as a plain offset omega d) misses by far more than the bound.
  ChainValues v;
  v.apply_spec("amplitude_imbalance:alpha=0.002");
  v.apply_spec("delay:d=2e-3");
  const Bench b;
  double worst = 0.0;
  for (int i = 0; i < kGrid; ++i) {
    const SignatureRow r = row_at(b, i);
    AngleBasis unshifted;
    unshifted.set(r, BasisTransform{});
    SignalValues m;
    m.rd = r.omega * 2e-3;
    find_effect("amplitude_imbalance")->contribution(r, unshifted, v.of(*find_effect("amplitude_imbalance")), m);
    worst = std::max(worst, std::abs(forward_signals(v, b, i).rd - m.rd));
  }
  EXPECT_GT(worst, 10.0 * 2e-5);
}

}  // namespace
}  // namespace resolver
