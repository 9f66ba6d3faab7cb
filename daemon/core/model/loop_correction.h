// The R/D converter's loop at real envelope magnitudes: what the linear filter misses.
//
// Why: the converter's error detector is e = s cos(phi) - c sin(phi) (tracking_loop.h),
// which for envelopes of radius A = 1 + r and angle psi is A sin(psi - phi): the loop's
// gain is the envelopes' radius. The fit's R/D prediction passes the envelope error
// e(theta) through the linearised loop H order by order (envelope_spectrum.h), i.e. it
// takes A = 1 and sin x = x. With a gain error of 10 % the radius carries +-5 % at
// 2 theta and a 5 % mean: measured on resolver-sim logs at 600-1500 r/min (p_r 3, a
// 3000 rad/s loop), the loop's omega_n came out 64-75 rad/s high (53-325 standard errors)
// and the tracking error times the radius ripple (a 4 theta term of 4e-5 rad, 1.8x the
// floor with an 8 % gain error and a 3 % k3) was named as a winding or mechanical harmonic
// that is not there.
//
// What: at a constant speed w every signal is periodic in the envelopes' angle phi.
// With D = psi - phi_rd the loop's tracking error and G(s) = 2 zeta wn s + wn^2,
//   s^2 phi_rd = G [(1 + r) sin D]  and  psi = theta - e
// give, with H = G / (s^2 + G) (the linear loop) and (1 - H) theta = 0 (type II),
//   D = -(1 - H) e - H [N(D)],   N(D) = (1 + r) sin D - D,
// and the R/D angle's error theta - phi_rd = e + D = H e - H [N(D)].
// The first term is the linear prediction; the second, c(phi) = -H[N(D)], is this
// correction: to first order H[r (1 - H) e], the radius ripple times the linear
// tracking error, filtered. It is solved by harmonic balance: on kGridPoints angles,
// D's Fourier coefficients are iterated (H is diagonal in the orders, N is pointwise)
// until they move by less than 1e-15 rad; the contraction factor is about |H| |r|
// (0.1 at a 15 % gain error), so ~15 iterations. A lightly damped loop (zeta <~ 0.05 at
// gain errors >~ 10 %) amplifies the orders the ripple couples near its resonance and the
// iteration diverges there; Newton's method on the grid then solves the same equations
// (loop_correction.cpp newton). Where that fails too (the catalog's extremes: zeta 0.01,
// a 50 % gain error, the ripple at the resonance) the loop has no periodic steady state:
// the correction is left out, the node says so, and the fit is not called converged.
//
// c depends on the speed through H(j k w): it is solved at speed nodes spaced
// kNodeWidth of the narrowest loop feature the series reaches (zeta wn / order) and
// interpolated linearly between them, nodes computed when a row first needs them.
// Interpolation error: (spacing / width)^2 / 8 = 5e-5 of the largest correction (4e-3 rad
// with a 15 % gain error, 3 % quadrature and a 3.6 % k3 at 1800 rad/s): 2e-7 rad at most
// (measured 1.6e-9), far below a 16-bit converter's quantization floor (2.8e-5 rad). loop_correction_test checks it against the exact nodes and the whole
// prediction against the simulated loop (RK4 of the nonlinear detector).
//
// Under a constant acceleration a the loop lags by L = a / wn^2 (the loop effect's linear
// term), which enters D as a constant: N(D) then carries r L, the radius ripple times the
// lag (2.6e-6 rad at 2 theta on a 0-1500 r/min ramp in 1.5 s with a 15 % gain error, which
// biased the quadrature by 6 standard errors). It is kept to first order in L (the rest is
// r^2 L and L D^2: < 2e-7 rad at such a ramp): per node, dc/dL from delta = 1 - H[N'(D) delta].
//
// Left out: speed changes within the loop's settling time (quasi-static at the row's
// speed and acceleration), and the
// radius and tracking error of effects that are not envelope effects (a delay's, an
// eccentricity's: their tracking error times the radius ripple is second order in
// two small effects).
#pragma once

#include <array>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "daemon/core/effects/signature.h"
#include "daemon/core/effects/tracking_loop.h"
#include "daemon/core/model/envelope_spectrum.h"

namespace resolver {

/// Node spacing as a share of the loop's narrowest feature the series reaches (header).
inline constexpr double kNodeWidth = 0.02;

/// The correction's Fourier series in phi at one speed, c_cos[n] cos(n phi) + c_sin[n] sin(n phi),
/// and its derivative in the acceleration lag L = a / wn^2 (g_cos, g_sin; header).
struct LoopCorrectionSeries {
  /// The orders whose coefficients are not negligible (kDropBelow, envelope_spectrum.h) and
  /// theirs; a zero where one of c and g has none.
  std::vector<int> k;
  std::vector<double> c_cos, c_sin, g_cos, g_sin;
  bool converged = true;  ///< a periodic steady state was found (else no correction: header)
  /// [rad] at the basis' envelope angle with lag `lag` [rad].
  [[nodiscard]] double at(const AngleBasis& basis, double lag = 0.0) const;
};

class LoopCorrection {
 public:
  /// The envelope series of the model (e and r) under `loop` (active: omega_n > 0).
  LoopCorrection(const EnvelopeSeries& series, const TrackingLoopParams& loop);

  [[nodiscard]] const TrackingLoopParams& loop() const { return loop_; }
  /// [rad] the correction to the R/D angle's error at the basis' envelope angle and
  /// the row's speed (interpolated between nodes; 0 when nothing is modulated).
  [[nodiscard]] double at(const AngleBasis& basis) const;
  /// The harmonic balance at speed `omega` [rad/s, resolver electrical], exactly.
  [[nodiscard]] LoopCorrectionSeries solve(double omega) const;
  /// Whether the balance converged at the nodes `at` interpolates for a row at speed
  /// `omega` (not: |H| |r| >= 1, the last iterate is no steady state; model_discovery
  /// says so and does not call such a fit explained).
  [[nodiscard]] bool converged_at(double omega) const;
  /// [rad/s] spacing of the speed nodes.
  [[nodiscard]] double spacing() const { return spacing_; }

 private:
  const LoopCorrectionSeries& node(std::int64_t i) const;

  TrackingLoopParams loop_;
  bool active_ = false;
  double spacing_ = 1.0;
  std::array<double, kGridPoints> e_{}, r_{};  ///< e(phi_j), r(phi_j) on the grid
  mutable std::unordered_map<std::int64_t, LoopCorrectionSeries> nodes_;
};

}  // namespace resolver
