// Each fittable catalog effect's small-parameter signature, as linear
// regressors on the rows model_discovery.h builds:
//   rd:   position error eps = theta_true - theta_rd                      [rad]
//   s, c: sin/cos envelope deviation s/A - sin theta, c/A - cos theta    [1]
// theta is the TRUE resolver electrical angle, theta_m the true mechanical one.
// Signs follow the effect headers in daemon/core/effects (eps = theta - phi):
//   amplitude_imbalance  alpha:  rd sin 2theta / (2 + alpha_hat)         c cos theta          (Hanselman 5, 16)
//   quadrature           beta:   rd -(1/2)(1 - cos 2theta)    c -sin theta         (quadrature.h: sign verified)
//   offsets              o_s:    rd -cos theta                 s 1                  (offsets.h)
//                        o_c:    rd  sin theta                 c 1
//   harmonics            k3:     rd -sin 2theta                s sin 3theta, c cos 3theta (Hanselman 8-9)
//   sampling_skew        tau:    rd 0 (the R/D converter does not see the DSP's skew)
//                                c -omega sin theta            (cos(theta + omega tau), sampling_skew.h)
//   mounting_offset      theta_0 [rad, motor electrical]: the resolver sees theta + (p_r/p) theta_0
//                                rd -(p_r/p)                   s (p_r/p) cos theta, c -(p_r/p) sin theta
//   eccentricity         e cos(phase), e sin(phase) [rad, mechanical]: the resolver sees
//                        theta + p_r e sin(theta_m + phase)  (eccentricity.h)
//                                rd -p_r sin theta_m, -p_r cos theta_m; s/c as a rotation
//   tracking_loop        omega_n [rad/s] (zeta assumed 0.7): not a column. The R/D angle
//                        is the static angle through the closed loop H(s) (tracking_loop.h),
//                        so every rd term at frequency k omega is multiplied by
//                        H(j k omega) = g e^{j phi}: sin(k theta) -> g sin(k theta + phi).
//                        Constant speed has no lag (type II); acceleration lag is ignored.
// Current-side effects act on the phase currents only. Their rows are the dq
// currents computed with the reference angle (theta_e = p theta_m), so the resolver's
// own errors do not enter them; the regressors are the effects' exact dq signatures
// (daemon/core/effects/*_dq_error) per unit parameter, taken at the mean measured
// current I0 = (i_d0, i_q0) (the machine carries the commanded current, Hwang's
// ideal-control picture; products of a gain error with its own DC shift are dropped):
//   current_offsets       off_a, off_b [A]: 1x theta_e ripple            (current_offsets.h)
//   current_gain_mismatch gain_a, gain_b [1]: DC shift + 2x theta_e ripple (current_gain_mismatch.h)
//   dead_time             t_d [s]: 6x theta_e ripple perpendicular to I0   (dead_time.h)
// Omitted terms are second order in the parameters (products of effects).
#pragma once

#include <span>
#include <string_view>

namespace resolver {

struct SignatureContext {
  double theta = 0.0;    ///< [rad] true resolver electrical angle
  double theta_m = 0.0;  ///< [rad] true mechanical angle (only with a reference)
  double omega = 0.0;    ///< [rad/s] resolver electrical speed
  int p_r = 3;
  int p = 3;
  double omega_n = 0.0;  ///< [rad/s] tracking-loop filter on the rd terms; 0 = none
  double zeta = 0.7;
  /// [1] current estimate of alpha: the exact sin 2theta coefficient of the R/D angle is
  /// alpha / (2 + alpha) (angle_error_fourier.h), while the cos envelope carries alpha
  /// itself; linearising at alpha_hat keeps the two signals consistent to O(alpha^3).
  double alpha_hat = 0.0;
  double theta_e = 0.0;  ///< [rad] true motor electrical angle (current rows only)
  double i_d0 = 0.0;     ///< [A] mean measured d current (current rows only)
  double i_q0 = 0.0;     ///< [A] mean measured q current
};

struct EffectSignature {
  std::string_view effect;
  std::span<const std::string_view> params;
  bool needs_reference;  ///< mechanical angle or absolute constant needed
  bool nonlinear;        ///< tracking_loop: searched, no columns
  std::string_view physics;  ///< one sentence: what the effect does to the signals
  /// Fills rd[i], s[i], c[i] for each parameter i. nullptr for nonlinear and current-side effects.
  void (*regress)(const SignatureContext&, double* rd, double* s, double* c);
  /// Current-side effects: fills d[i], q[i] [A per unit parameter]. nullptr for resolver effects.
  void (*regress_dq)(const SignatureContext&, double* d, double* q) = nullptr;
  [[nodiscard]] bool current_side() const { return regress_dq != nullptr; }
};

/// The fittable effects, in catalog order.
[[nodiscard]] std::span<const EffectSignature> effect_signatures();
/// nullptr when `effect` has no signature here.
[[nodiscard]] const EffectSignature* find_signature(std::string_view effect);

/// g sin(k angle + phi) (sine = true) or g cos(k angle + phi), with g e^{j phi} =
/// H(j k angle_speed) of the context's tracking loop (g = 1, phi = 0 without one,
/// or for k = 0). angle_speed [rad/s] is the angle's own speed.
[[nodiscard]] double filtered_harmonic(const SignatureContext& ctx, double k, double angle, double angle_speed,
                                       bool sine);

}  // namespace resolver
