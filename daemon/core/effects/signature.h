// What an effect's signature sees of one sample, and what it returns.
//
// The fit compares five signals with the model (all deviations from an ideal chain):
//   rd     position error of the R/D angle       eps = theta_true - theta_rd             [rad]
//   sa     position error of the sin/cos angle   theta_true - atan2(s, c)                [rad]
//   sr     radius deviation of the envelopes     sqrt(s^2 + c^2) / A - 1                 [1]
//   d, q   dq currents in the frame of the true motor angle theta_e = p theta_m         [A]
// The envelopes enter as angle and radius, not as s and c: a constant rotation
// (mounting offset, delay at one speed, backlash) is then exactly a constant of sa
// however large, where the s/c deviations would be linear only for small angles.
// To first order an envelope deviation (ds, dc) at angle theta is
//   sa = sin(theta) dc - cos(theta) ds,   sr = sin(theta) ds + cos(theta) dc.
// Each effect gives, per parameter, the derivative of each signal (its column),
// evaluated at the true angles of the row (first order in the small parameters,
// as the effect headers derive them).
//
// The R/D converter sits between the envelopes and the rd signal: an error
// harmonic of the envelope angle reaches the R/D angle through the converter's
// closed loop H(s) (tracking_loop.h) and late by the chain's delay d. AngleBasis
// applies both, so an effect writes its rd column with basis.rd_sin(k) etc. and
// never needs to know which converter or delay the model has:
//   rd_sin(k) = |H(j k omega)| sin(k (theta - omega d) + arg H(j k omega))
// The envelopes carry the delay but not the loop: env_sin(k) = sin(k (theta - omega d)).
#pragma once

#include <algorithm>
#include <complex>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include "daemon/core/effects/tracking_loop.h"

namespace resolver {

/// The true angle at earlier times: the fit's rows around the current one (a
/// delay needs theta(t - d) exactly, also across a speed step). Valid only while
/// the row is being evaluated.
struct AngleHistory {
  const void* context = nullptr;
  /// [rad] the true resolver angle at time t [s] (interpolated between rows), or NaN
  /// when t is before the rows the context holds.
  double (*angle_at)(const void* context, std::size_t index, double t) = nullptr;
  std::size_t index = 0;
};

/// One sample as the signatures see it (true angles from the reference, or the
/// speed-smoothed ideal angle without one).
struct SignatureRow {
  double t = 0.0;          ///< [s] sample time from the log's first sample
  double theta = 0.0;      ///< [rad] true resolver electrical angle (continuous)
  double theta_m = 0.0;    ///< [rad] true mechanical angle (continuous; with a reference)
  double omega = 0.0;      ///< [rad/s] resolver electrical speed (signed)
  double accel = 0.0;      ///< [rad/s^2] resolver electrical acceleration
  double direction = 1.0;  ///< +1 / -1: direction of motion (held through a standstill)
  /// [rad, mechanical] travel since the last reversal of direction (from its turning
  /// point); infinity when the rotor has not reversed. Backlash's take-up needs it.
  double since_reversal = std::numeric_limits<double>::infinity();
  double theta_e = 0.0;    ///< [rad] true motor electrical angle (currents only)
  double i_d0 = 0.0;       ///< [A] operating point: mean measured d current
  double i_q0 = 0.0;       ///< [A] mean measured q current
  int p_r = 1;             ///< resolver pole pairs
  int p = 1;               ///< motor pole pairs
  AngleHistory history;    ///< earlier true angles (none: extrapolate with omega, accel)

  /// [rad] the true resolver angle at time `t_at` [s] <= t: from the history when it
  /// reaches back that far, else extrapolated theta - omega dt - accel dt^2 / 2... with
  /// dt = t - t_at (exact at constant acceleration).
  [[nodiscard]] double theta_at(double t_at) const {
    if (history.angle_at != nullptr) {
      const double v = history.angle_at(history.context, history.index, t_at);
      if (v == v) return v;  // not NaN
    }
    const double dt = t - t_at;
    return theta - omega * dt + 0.5 * accel * dt * dt;
  }
};

/// The five signals' values (a prediction or one column).
struct SignalValues {
  double rd = 0.0;  ///< [rad]
  double sa = 0.0;  ///< [rad]
  double sr = 0.0;  ///< [1]
  double d = 0.0;   ///< [A]
  double q = 0.0;   ///< [A]
  SignalValues& operator+=(const SignalValues& o) {
    rd += o.rd;
    sa += o.sa;
    sr += o.sr;
    d += o.d;
    q += o.q;
    return *this;
  }
};

/// One column per parameter of one effect (storage owned by the caller, sized to
/// the effect's parameter count: no fixed-size buffers).
class SignatureColumns {
 public:
  explicit SignatureColumns(std::span<SignalValues> storage) : cols_(storage) {}
  [[nodiscard]] std::size_t size() const { return cols_.size(); }
  SignalValues& col(std::size_t i) { return cols_[i]; }
  [[nodiscard]] const SignalValues& col(std::size_t i) const { return cols_[i]; }
  void clear() {
    for (auto& c : cols_) c = SignalValues{};
  }

 private:
  std::span<SignalValues> cols_;
};

/// The transform the effects that move the resolver's angle or filter it set on
/// every other effect's harmonics (configure_basis).
struct BasisTransform {
  TrackingLoopParams loop;  ///< the R/D converter's loop (tracking_loop.h); omega_n = 0: no filtering
  double delay = 0.0;    ///< [s] the resolver signals are those of t - delay
  /// [rad, resolver electrical] the angle the resolver sees is the true one plus this
  /// (mounting offset, backlash, eccentricity, mechanical harmonics): the windings'
  /// errors are functions of the seen angle, so their harmonics turn with it.
  double shift = 0.0;
};

/// Harmonics of the true angles as each signal sees them (see the header comment).
/// Reused across rows: set() recomputes only what is asked for.
class AngleBasis {
 public:
  AngleBasis() = default;
  /// Prepares the basis for `row` under `transform`. Cannot fail.
  void set(const SignatureRow& row, const BasisTransform& transform);

  /// sin / cos (k theta) as the R/D angle sees an error harmonic of order k >= 0.
  [[nodiscard]] double rd_sin(int k) const;
  [[nodiscard]] double rd_cos(int k) const;
  /// sin / cos (n theta_m) as the R/D angle sees a mechanical error harmonic of order n >= 0.
  [[nodiscard]] double rd_mech_sin(int n) const;
  [[nodiscard]] double rd_mech_cos(int n) const;
  /// sin / cos (k theta') of the envelopes' angle theta' = theta - omega d.
  [[nodiscard]] double env_sin(int k) const;
  [[nodiscard]] double env_cos(int k) const;
  /// sin / cos (n theta_m') of the mechanical angle the envelopes carry.
  [[nodiscard]] double env_mech_sin(int n) const;
  [[nodiscard]] double env_mech_cos(int n) const;
  /// H(j k omega) of the R/D loop for order k of the resolver angle (1 without a loop), its
  /// frequency ramping at k accel (tracking_loop.h):
  /// rd_sin(k) = Re(H) env_sin(k) + Im(H) env_cos(k); rd_cos(k) = Re(H) env_cos(k) - Im(H) env_sin(k).
  /// Each order's is computed once per row (a fit reads it for the prediction and for every
  /// envelope column: a quarter of a fit's time with a loop in the model before).
  [[nodiscard]] std::complex<double> rd_response(int k) const {
    if (k == 0) return {1.0, 0.0};
    const auto i = static_cast<std::size_t>(k);
    if (i >= responses_.size()) responses_.resize(std::max<std::size_t>(i + 1, 2 * responses_.size() + 16));
    Response& r = responses_[i];
    if (r.row != rows_set_) r = {rows_set_, tracking_loop_response(transform_.loop, k * row_.omega, k * row_.accel)};
    return r.h;
  }
  /// False when no tracking loop filters the R/D angle: rd_sin(k) == env_sin(k) then,
  /// and a caller summing both may compute one.
  [[nodiscard]] bool rd_filtered() const { return tracking_loop_active(transform_.loop); }
  /// [rad] the envelopes' resolver angle theta(t - d) + shift and mechanical angle theta_m(t - d).
  [[nodiscard]] double env_angle() const { return env_.angle; }
  [[nodiscard]] double env_mech_angle() const { return mech_.angle; }
  /// The closed loop's gain and phase at angular frequency w [rad/s] (1, 0 without a loop).
  [[nodiscard]] double loop_gain(double w) const;
  [[nodiscard]] double loop_phase(double w) const;

  [[nodiscard]] const SignatureRow& row() const { return row_; }
  [[nodiscard]] const BasisTransform& transform() const { return transform_; }

 private:
  struct Series {  // sin/cos(k a) for k = 0..n by rotation, computed lazily
    double angle = 0.0;
    mutable std::vector<double> s, c;
    void reset(double a) {
      angle = a;
      s.clear();
      c.clear();
    }
    void grow(int k) const;
    // Inline fast path: a fit reads the same orders of a row many times (a quarter
    // of explain's time was the out-of-line call before it).
    [[nodiscard]] double sin_k(int k) const {
      const auto i = static_cast<std::size_t>(k);
      if (i >= s.size()) grow(k);
      return s[i];
    }
    [[nodiscard]] double cos_k(int k) const {
      const auto i = static_cast<std::size_t>(k);
      if (i >= c.size()) grow(k);
      return c[i];
    }
  };
  /// g sin(k a + phi) or g cos(k a + phi) with g e^{j phi} = H(j k w).
  [[nodiscard]] double filtered(const Series& series, int k, double w, double w_rate, bool sine) const;

  /// rd_response(k) by k, valid for the row set as the `row`-th (set() counts them: no
  /// clearing per row, which cost as much as the responses it kept).
  struct Response {
    std::uint64_t row = 0;
    std::complex<double> h;
  };
  SignatureRow row_;
  BasisTransform transform_;
  std::uint64_t rows_set_ = 0;
  mutable std::vector<Response> responses_;
  Series env_;   // theta - omega d
  Series mech_;  // theta_m - omega_m d
};

/// The column of a parameter that shifts the angle the resolver sees by `shift`
/// [rad, resolver electrical, per unit parameter]: the envelopes turn with it (sa
/// = -shift, radius unchanged) and the R/D angle's error is `rd` (-shift, through
/// the converter when the shift varies with the angle).
[[nodiscard]] inline SignalValues shift_column(double rd, double shift) {
  return SignalValues{.rd = rd, .sa = -shift, .sr = 0.0};
}

/// The column of a parameter that changes the envelopes by (ds, dc) [1, per unit
/// parameter] at the envelopes' angle, with R/D angle error `rd` (see the header).
[[nodiscard]] inline SignalValues envelope_column(const AngleBasis& b, double rd, double ds, double dc) {
  const double sn = b.env_sin(1), cs = b.env_cos(1);
  return SignalValues{.rd = rd, .sa = sn * dc - cs * ds, .sr = sn * ds + cs * dc};
}

}  // namespace resolver
