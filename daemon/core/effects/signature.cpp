#include "daemon/core/effects/signature.h"

#include <cmath>
#include <complex>

namespace resolver {

void AngleBasis::Series::grow(int k) const {
  if (s.empty()) {
    s.push_back(0.0);
    c.push_back(1.0);
  }
  // Rotation by the first harmonic: error ~n ulp at order n, far below any floor
  // for the orders (<= ~40) used here, and one sincos per row instead of n.
  while (static_cast<int>(s.size()) <= k) {
    if (s.size() == 1) {
      s.push_back(std::sin(angle));
      c.push_back(std::cos(angle));
      continue;
    }
    const double s1 = s[1], c1 = c[1];
    const double sn = s.back(), cn = c.back();
    s.push_back(sn * c1 + cn * s1);
    c.push_back(cn * c1 - sn * s1);
  }
}

void AngleBasis::set(const SignatureRow& row, const BasisTransform& transform) {
  row_ = row;
  transform_ = transform;
  const double d = transform.delay;
  const double late = d != 0.0 ? row.theta_at(row.t - d) : row.theta;
  env_.reset(late + transform.shift);
  mech_.reset(row.theta_m + (late - row.theta) / static_cast<double>(row.p_r));
}

std::complex<double> AngleBasis::loop_response(double w) const {
  // H(jw) = (a + ib) / (c + ib), a = wn^2, b = 2 zeta wn w, c = wn^2 - w^2 (tracking_loop.h),
  // divided out by hand: std::complex's division (__divdc3, with its inf and NaN cases)
  // was a tenth of a fit's time; c^2 + b^2 > 0 for zeta > 0 (its range starts at 0.01).
  const double wn = transform_.omega_n;
  const double a = wn * wn, b = 2.0 * transform_.zeta * wn * w, c = a - w * w;
  const double inv = 1.0 / (c * c + b * b);
  return {(a * c + b * b) * inv, (b * c - a * b) * inv};
}

double AngleBasis::loop_gain(double w) const {
  return transform_.omega_n > 0.0 ? std::abs(loop_response(w)) : 1.0;
}

double AngleBasis::loop_phase(double w) const {
  return transform_.omega_n > 0.0 ? std::arg(loop_response(w)) : 0.0;
}

double AngleBasis::filtered(const Series& series, int k, double w, bool sine) const {
  const double sk = series.sin_k(k), ck = series.cos_k(k);
  if (k == 0 || !(transform_.omega_n > 0.0)) return sine ? sk : ck;
  const std::complex<double> h = loop_response(w);
  // g sin(x + phi) = Re(h) sin x + Im(h) cos x;  g cos(x + phi) = Re(h) cos x - Im(h) sin x.
  return sine ? h.real() * sk + h.imag() * ck : h.real() * ck - h.imag() * sk;
}

double AngleBasis::rd_sin(int k) const { return filtered(env_, k, k * row_.omega, true); }
double AngleBasis::rd_cos(int k) const { return filtered(env_, k, k * row_.omega, false); }
double AngleBasis::rd_mech_sin(int n) const {
  return filtered(mech_, n, n * row_.omega / static_cast<double>(row_.p_r), true);
}
double AngleBasis::rd_mech_cos(int n) const {
  return filtered(mech_, n, n * row_.omega / static_cast<double>(row_.p_r), false);
}
double AngleBasis::env_sin(int k) const { return env_.sin_k(k); }
double AngleBasis::env_cos(int k) const { return env_.cos_k(k); }
double AngleBasis::env_mech_sin(int n) const { return mech_.sin_k(n); }
double AngleBasis::env_mech_cos(int n) const { return mech_.cos_k(n); }

}  // namespace resolver
