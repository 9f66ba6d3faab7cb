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
  ++rows_set_;  // every order's response is computed again (rd_response)
  const double d = transform.delay;
  const double late = d != 0.0 ? row.theta_at(row.t - d) : row.theta;
  env_.reset(late + transform.shift);
  mech_.reset(row.theta_m + (late - row.theta) / static_cast<double>(row.p_r));
}

double AngleBasis::loop_gain(double w) const { return tracking_loop_gain(transform_.loop, w); }

double AngleBasis::loop_phase(double w) const { return tracking_loop_phase(transform_.loop, w); }

double AngleBasis::filtered(const Series& series, int k, double w, double w_rate, bool sine) const {
  const double sk = series.sin_k(k), ck = series.cos_k(k);
  if (k == 0 || !rd_filtered()) return sine ? sk : ck;
  const std::complex<double> h = tracking_loop_response(transform_.loop, w, w_rate);
  // g sin(x + phi) = Re(h) sin x + Im(h) cos x;  g cos(x + phi) = Re(h) cos x - Im(h) sin x.
  return sine ? h.real() * sk + h.imag() * ck : h.real() * ck - h.imag() * sk;
}

double AngleBasis::rd_sin(int k) const {
  if (k == 0 || !rd_filtered()) return env_.sin_k(k);
  const std::complex<double> h = rd_response(k);
  return h.real() * env_.sin_k(k) + h.imag() * env_.cos_k(k);
}
double AngleBasis::rd_cos(int k) const {
  if (k == 0 || !rd_filtered()) return env_.cos_k(k);
  const std::complex<double> h = rd_response(k);
  return h.real() * env_.cos_k(k) - h.imag() * env_.sin_k(k);
}
double AngleBasis::rd_mech_sin(int n) const {
  const double p_r = row_.p_r;
  return filtered(mech_, n, n * row_.omega / p_r, n * row_.accel / p_r, true);
}
double AngleBasis::rd_mech_cos(int n) const {
  const double p_r = row_.p_r;
  return filtered(mech_, n, n * row_.omega / p_r, n * row_.accel / p_r, false);
}
double AngleBasis::env_sin(int k) const { return env_.sin_k(k); }
double AngleBasis::env_cos(int k) const { return env_.cos_k(k); }
double AngleBasis::env_mech_sin(int n) const { return mech_.sin_k(n); }
double AngleBasis::env_mech_cos(int n) const { return mech_.cos_k(n); }

}  // namespace resolver
