#include "daemon/core/discovery/effect_signatures.h"

#include <array>
#include <cmath>
#include <complex>

#include "daemon/core/effects/current_gain_mismatch.h"
#include "daemon/core/effects/current_offsets.h"
#include "daemon/core/effects/dead_time.h"

namespace resolver {

namespace {

// Shorthands: a harmonic of the true resolver angle with the context's loop filter.
double rd_sin(const SignatureContext& x, double k) { return filtered_harmonic(x, k, x.theta, x.omega, true); }
double rd_cos(const SignatureContext& x, double k) { return filtered_harmonic(x, k, x.theta, x.omega, false); }

void amplitude_imbalance(const SignatureContext& x, double* rd, double* s, double* c) {
  rd[0] = rd_sin(x, 2.0) / (2.0 + x.alpha_hat);
  s[0] = 0.0;
  c[0] = std::cos(x.theta);
}

void quadrature(const SignatureContext& x, double* rd, double* s, double* c) {
  rd[0] = -0.5 * (1.0 - rd_cos(x, 2.0));
  s[0] = 0.0;
  c[0] = -std::sin(x.theta);
}

void offsets(const SignatureContext& x, double* rd, double* s, double* c) {
  rd[0] = -rd_cos(x, 1.0);  // o_s
  s[0] = 1.0;
  c[0] = 0.0;
  rd[1] = rd_sin(x, 1.0);  // o_c
  s[1] = 0.0;
  c[1] = 1.0;
}

void harmonics(const SignatureContext& x, double* rd, double* s, double* c) {
  rd[0] = -rd_sin(x, 2.0);  // k3: -K_3 sin((3 - 1) theta)
  s[0] = std::sin(3.0 * x.theta);
  c[0] = std::cos(3.0 * x.theta);
}

void sampling_skew(const SignatureContext& x, double* rd, double* s, double* c) {
  rd[0] = 0.0;
  s[0] = 0.0;
  c[0] = -x.omega * std::sin(x.theta);
}

void mounting_offset(const SignatureContext& x, double* rd, double* s, double* c) {
  const double r = static_cast<double>(x.p_r) / static_cast<double>(x.p);
  rd[0] = -r;
  s[0] = r * std::cos(x.theta);
  c[0] = -r * std::sin(x.theta);
}

void eccentricity(const SignatureContext& x, double* rd, double* s, double* c) {
  const double pr = static_cast<double>(x.p_r);
  const double wm = x.omega / pr;
  // Parameters a = e cos(phase), b = e sin(phase): e sin(theta_m + phase) = a sin theta_m + b cos theta_m.
  const double basis[2] = {filtered_harmonic(x, 1.0, x.theta_m, wm, true),
                           filtered_harmonic(x, 1.0, x.theta_m, wm, false)};
  const double raw[2] = {std::sin(x.theta_m), std::cos(x.theta_m)};
  for (int i = 0; i < 2; ++i) {
    rd[i] = -pr * basis[i];
    s[i] = pr * raw[i] * std::cos(x.theta);
    c[i] = -pr * raw[i] * std::sin(x.theta);
  }
}

// Current side: each signature is linear in its parameters, so the column of a
// parameter is the effect's dq error with that parameter at 1 and the others at 0.
void current_offsets(const SignatureContext& x, double* d, double* q) {
  const DqCurrents a = current_offsets_dq_error(CurrentOffsets{1.0, 0.0}, x.theta_e);
  const DqCurrents b = current_offsets_dq_error(CurrentOffsets{0.0, 1.0}, x.theta_e);
  d[0] = a.d;
  q[0] = a.q;
  d[1] = b.d;
  q[1] = b.q;
}

void current_gain_mismatch(const SignatureContext& x, double* d, double* q) {
  const DqCurrents a = current_gain_mismatch_dq_error(CurrentGainMismatch{1.0, 0.0}, x.i_d0, x.i_q0, x.theta_e);
  const DqCurrents b = current_gain_mismatch_dq_error(CurrentGainMismatch{0.0, 1.0}, x.i_d0, x.i_q0, x.theta_e);
  d[0] = a.d;
  q[0] = a.q;
  d[1] = b.d;
  q[1] = b.q;
}

void dead_time(const SignatureContext& x, double* d, double* q) {
  const DqCurrents a = dead_time_dq_error(DeadTime{1.0}, x.i_d0, x.i_q0, x.theta_e);  // per second of t_d
  d[0] = a.d;
  q[0] = a.q;
}

constexpr std::array<std::string_view, 1> kAlpha{"alpha"};
constexpr std::array<std::string_view, 1> kBeta{"beta"};
constexpr std::array<std::string_view, 2> kOffsets{"o_s", "o_c"};
constexpr std::array<std::string_view, 1> kK3{"k3"};
constexpr std::array<std::string_view, 1> kTau{"tau"};
constexpr std::array<std::string_view, 1> kOmegaN{"omega_n"};
constexpr std::array<std::string_view, 1> kTheta0{"theta_0"};
constexpr std::array<std::string_view, 2> kEcc{"e_cos_phase", "e_sin_phase"};
constexpr std::array<std::string_view, 2> kCurrentOffsets{"off_a", "off_b"};
constexpr std::array<std::string_view, 2> kGains{"gain_a", "gain_b"};
constexpr std::array<std::string_view, 1> kDeadTime{"t_d"};

constexpr std::array<EffectSignature, 11> kSignatures{{
    {"amplitude_imbalance", kAlpha, false, false,
     "a gain error of the cos channel: position error at 2 theta in phase with sin 2 theta, independent of speed, "
     "and a cos-envelope amplitude off by alpha",
     amplitude_imbalance},
    {"quadrature", kBeta, false, false,
     "the cos winding is not at 90 degrees: position error at 2 theta in phase with cos 2 theta plus a constant, "
     "independent of speed, seen by the R/D angle and the sin/cos signals alike",
     quadrature},
    {"offsets", kOffsets, false, false,
     "DC offsets on the demodulated envelopes: position error at 1x theta, envelopes shifted by a constant",
     offsets},
    {"harmonics", kK3, false, false,
     "a 3rd inductance harmonic of the windings: lands on 2 theta in the angle like alpha, but appears at 3 theta "
     "in both envelopes (Hanselman eq. 8-9)",
     harmonics},
    {"sampling_skew", kTau, false, false,
     "the cos channel is sampled after the sin channel: a quadrature-like error of the sin/cos pair that grows "
     "with speed and that the R/D angle does not show",
     sampling_skew},
    {"tracking_loop", kOmegaN, false, true,
     "the R/D converter's closed loop filters the error harmonics: the 2 theta ripple of the R/D angle changes in "
     "amplitude and phase with speed, the sin/cos signals do not",
     nullptr},
    {"eccentricity", kEcc, true, false,
     "the rotor is not concentric: a 1x mechanical harmonic of the position error (order 1/p_r of theta), only "
     "visible against the reference encoder",
     eccentricity},
    {"mounting_offset", kTheta0, true, false,
     "the resolver is mounted at an angle: a constant position error against the reference, at every speed",
     mounting_offset},
    {"current_offsets", kCurrentOffsets, true, false,
     "DC offsets of the phase current sensors: i_d and i_q ripple at 1x theta_e, a quarter period apart, "
     "independent of load and speed; the resolver signals are clean",
     nullptr, current_offsets},
    {"current_gain_mismatch", kGains, true, false,
     "the phase current sensors differ in gain: i_d and i_q ripple at 2x theta_e proportional to the current, "
     "while the resolver signals are clean (so it is not the resolver's amplitude imbalance)",
     nullptr, current_gain_mismatch},
    {"dead_time", kDeadTime, true, false,
     "inverter dead time: 5th and 7th harmonics of the phase currents, i.e. a 6x theta_e ripple on i_d and i_q "
     "perpendicular to the current vector",
     nullptr, dead_time},
}};

}  // namespace

std::span<const EffectSignature> effect_signatures() { return kSignatures; }

const EffectSignature* find_signature(std::string_view effect) {
  for (const auto& s : kSignatures) {
    if (s.effect == effect) return &s;
  }
  return nullptr;
}

double filtered_harmonic(const SignatureContext& ctx, double k, double angle, double angle_speed, bool sine) {
  double phase = k * angle;
  double gain = 1.0;
  if (ctx.omega_n > 0.0 && k != 0.0) {
    // H(jw) = (wn^2 + j 2 zeta wn w) / (wn^2 - w^2 + j 2 zeta wn w), tracking_loop.h.
    const double w = k * angle_speed;
    const double wn = ctx.omega_n;
    const std::complex<double> num(wn * wn, 2.0 * ctx.zeta * wn * w);
    const std::complex<double> den(wn * wn - w * w, 2.0 * ctx.zeta * wn * w);
    const std::complex<double> h = num / den;
    gain = std::abs(h);
    phase += std::arg(h);
  }
  return gain * (sine ? std::sin(phase) : std::cos(phase));
}

}  // namespace resolver
