// Signal-domain least squares on the demodulated sin/cos envelopes
// (Heydemann-style ellipse fit, extended with Hanselman's inductance harmonics).
//
// Model: the effect catalog's forward model (daemon/core/effects/sensor_chain.h)
// in signal units [counts or any unit]:
//   s = A [ sin t + sum_n K_n sin(n t) ]                    + A o_s      (Hanselman eq. 8)
//   c = A (1 + alpha) [ cos(t + beta) + sum_n K_n cos(n t) ] + A o_c      (eqs. 4, 6, 16)
// t the resolver electrical angle [rad]. K_0 adds A K_0 to s and A(1+alpha) K_0
// to c: it is indistinguishable from the offsets and is reported inside o_s, o_c.
//
// Two fits share the same per-sample stream:
//
// A. Reference fit (a true angle theta_ref is known, t = theta_ref + delta):
//    both channels are linear in the regressors
//      phi(theta_ref) = [1, sin, cos, sin(n theta_ref), cos(n theta_ref) for each harmonic n]
//    so s = phi^T x_s, c = phi^T x_c are two ordinary LS problems with the same
//    normal matrix M = sum phi phi^T. With x_s = (S0, S1, S2, ...),
//    x_c = (C0, C2, C1, ...) (C2 multiplies sin, C1 cos):
//      S1 sin + S2 cos = A sin(theta_ref + delta)  -> A = hypot(S1, S2), delta = atan2(S2, S1)
//      C1 cos + C2 sin = B cos(theta_ref + gamma)  -> B = hypot(C1, C2), gamma = atan2(-C2, C1)
//      alpha = B / A - 1,  beta = gamma - delta,  o_s = S0 / A,  o_c = C0 / A
//      K_n from s: project (Ss_n, Sc_n) on sin(n(theta_ref + delta)):
//        K_n^s = (Ss_n cos(n delta) + Sc_n sin(n delta)) / A
//      K_n from c: project (Cs_n, Cc_n) on cos(n(theta_ref + delta)):
//        K_n^c = (Cc_n cos(n delta) - Cs_n sin(n delta)) / B
//      K_n = (A^2 K_n^s + B^2 K_n^c) / (A^2 + B^2)    (inverse-variance weights)
//    With fit_reference_offset = false, delta := 0 (the reference is aligned with
//    the sin channel) and A = S1; beta is then twice as precise (cramer_rao.h).
//
// B. Conic fit (no reference; the angle is unknown). With u = s - A o_s,
//    v = c - A o_c, B = A(1+alpha): sin t = u/A and cos t = (v/B + (u/A) sin beta)/cos beta,
//    so sin^2 + cos^2 = 1 gives the centred ellipse
//      u^2/A^2 + 2 sin(beta) u v/(A B) + v^2/B^2 = cos^2(beta).             (*)
//    The data are fitted to the general conic  a s^2 + b s c + e c^2 + d s + f c = 1
//    (linear in p = (a, b, e, d, f); an algebraic LS, nearly the geometric one for a
//    near-circle traced over whole revolutions). Conversion:
//      centre (S0, C0) solves [2a b; b 2e] (S0, C0)^T = -(d, f)^T (gradient = 0)
//      k = 1 + a S0^2 + b S0 C0 + e C0^2, so a u^2 + b u v + e v^2 = k, and with
//      P = a/k, Q = b/k, R = e/k, matching (*) after dividing by cos^2 beta:
//        P = 1/(A^2 cos^2 beta), Q = 2 sin beta/(A B cos^2 beta), R = 1/(B^2 cos^2 beta)
//      =>  sin beta = Q / (2 sqrt(P R)),  1 + alpha = sqrt(P / R),
//          A = 1 / (sqrt(P) cos beta),  o_s = S0 / A,  o_c = C0 / A.
//    Harmonics are not part of the conic (a conic cannot bend), and delta does not
//    exist: the angle is defined by the sin channel.
//
// Recursion: the normal equations are accumulated with exponential forgetting,
// M <- lambda M + phi phi^T (O(p^2) per sample), and solved on demand (LDLT).
// Standard errors: residual variance times the diagonal of M^-1, corrected for
// the weights w_k = lambda^k:
//   sigma^2 = RSS_w / W * n_eff / (n_eff - p),  Cov(x) = sigma^2 (W2 / W) M^-1,
//   W = sum w, W2 = sum w^2, n_eff = W^2 / W2   (exact OLS formulas for lambda = 1).
// For the reference fit the two channels' coefficient estimates are independent
// (independent noise), each with its own sigma. The converted parameters get the
// delta method: Cov(g(x)) = J Cov(x) J^T with J the Jacobian of the conversion
// above, taken by central differences.
//
// Numerics: samples are divided by a fixed scale before accumulating (config or
// the first sample's radius) so the conic's 4th-order sums stay near 1.
#pragma once

#include <Eigen/Dense>
#include <cstdint>
#include <optional>
#include <vector>

namespace resolver {

/// A value with its standard error (NaN when unknown).
struct Estimate {
  double value = 0.0;
  double std_error = 0.0;
};

struct SinCosLsConfig {
  /// Forgetting factor lambda in (0, 1]; memory ~ 1/(1 - lambda) samples. 1 = plain LS.
  double forgetting = 1.0;
  /// Harmonic orders n >= 2 fitted in the reference fit (e.g. {3}). Ignored by the conic fit.
  std::vector<int> harmonics;
  /// Reference fit: estimate the reference's constant offset delta (true angle =
  /// theta_ref + delta). false assumes the reference is aligned with the sin channel.
  bool fit_reference_offset = true;
  /// [signal units] normalisation of the accumulated sums; <= 0: the radius of the first sample.
  double scale = 0.0;
  /// Fewest samples before solve() returns a fit (must be > number of parameters).
  std::int64_t min_samples = 16;
  bool operator==(const SinCosLsConfig&) const = default;
};

enum class SinCosFitMethod : std::uint8_t { kReference, kConic };

struct SinCosFit {
  SinCosFitMethod method = SinCosFitMethod::kConic;
  Estimate amplitude;         ///< [signal units] A
  Estimate alpha;             ///< [1] cos-channel gain error
  Estimate beta;              ///< [rad] quadrature error
  Estimate o_s;               ///< [fraction of A] sin offset (includes K_0)
  Estimate o_c;               ///< [fraction of A] cos offset (includes (1+alpha) K_0)
  Estimate reference_offset;  ///< [rad] delta; value 0, std NaN when not fitted or conic
  std::vector<int> harmonic_orders;  ///< orders n of `k`
  std::vector<Estimate> k;           ///< [fraction of A] K_n (Hanselman eq. 8)
  double samples = 0.0;              ///< effective number of samples W (= count for lambda = 1)
  std::int64_t samples_seen = 0;     ///< samples added since construction/reset
  /// [signal units] rms residual per channel (reference fit) or rms radial
  /// residual (conic fit; algebraic residual times A/(2k), exact to first order).
  double residual_rms = 0.0;
};

/// State of the recursion: plain data, so it can be logged and reset.
struct SinCosLsState {
  double scale = 0.0;                 ///< normalisation in use (0 = not yet set)
  std::int64_t seen_reference = 0;
  std::int64_t seen_conic = 0;
  // Reference fit: M = sum w phi phi^T, and phi^T s, phi^T c, s^2, c^2, W, W2 sums.
  Eigen::MatrixXd ref_m;
  Eigen::VectorXd ref_bs, ref_bc;
  double ref_ss = 0.0, ref_cc = 0.0, ref_w = 0.0, ref_w2 = 0.0;
  // Conic fit: z = (s^2, s c, c^2, s, c), target 1.
  Eigen::Matrix<double, 5, 5> conic_m = Eigen::Matrix<double, 5, 5>::Zero();
  Eigen::Matrix<double, 5, 1> conic_b = Eigen::Matrix<double, 5, 1>::Zero();
  double conic_w = 0.0, conic_w2 = 0.0;
};

class SinCosLeastSquares {
 public:
  /// Throws std::invalid_argument (naming the field) when forgetting is not in
  /// (0, 1] or a harmonic order is < 2 or repeated.
  explicit SinCosLeastSquares(const SinCosLsConfig& config);

  /// Adds an (s, c) pair without reference: feeds the conic fit only.
  void add(double s, double c);
  /// Adds an (s, c) pair with the reference resolver electrical angle theta_ref
  /// [rad]: feeds the reference fit and the conic fit.
  void add(double s, double c, double theta_ref);

  /// The reference fit when at least min_samples reference samples were added,
  /// else the conic fit. nullopt while too few samples or when singular.
  [[nodiscard]] std::optional<SinCosFit> solve() const;
  /// nullopt: too few reference samples, or the normal matrix is singular (the
  /// angles did not cover a revolution).
  [[nodiscard]] std::optional<SinCosFit> solve_reference() const;
  /// nullopt: too few samples, or the conic is not an ellipse (degenerate data).
  [[nodiscard]] std::optional<SinCosFit> solve_conic() const;

  [[nodiscard]] const SinCosLsConfig& config() const { return config_; }
  [[nodiscard]] const SinCosLsState& state() const { return state_; }
  void reset();

 private:
  void set_scale(double s, double c);
  [[nodiscard]] int ref_params() const { return 3 + 2 * static_cast<int>(config_.harmonics.size()); }

  SinCosLsConfig config_;
  SinCosLsState state_;
};

}  // namespace resolver
