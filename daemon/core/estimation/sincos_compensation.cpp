#include "daemon/core/estimation/sincos_compensation.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include "daemon/core/angles.h"

namespace resolver {

SinCosCorrection SinCosCorrection::from_fit(const SinCosFit& fit) {
  SinCosCorrection c;
  c.amplitude = fit.amplitude.value;
  c.alpha = fit.alpha.value;
  c.beta = fit.beta.value;
  c.o_s = fit.o_s.value;
  c.o_c = fit.o_c.value;
  c.orders = fit.harmonic_orders;
  for (const Estimate& e : fit.k) c.k.push_back(e.value);
  return c;
}

namespace {

// Offsets and gain removed: {sin t + harmonics, cos(t + beta) + harmonics}.
SinCos remove_offsets_and_gain(const SinCosCorrection& corr, double s, double c) {
  return {s / corr.amplitude - corr.o_s, (c / corr.amplitude - corr.o_c) / (1.0 + corr.alpha)};
}

}  // namespace

SinCos correct_sincos(const SinCosCorrection& corr, double s, double c) {
  SinCos u = remove_offsets_and_gain(corr, s, c);
  const double sb = std::sin(corr.beta);
  const double cb = std::cos(corr.beta);
  if (!corr.k.empty()) {
    // First-pass angle with quadrature removed, then subtract the harmonics there.
    const double t0 = std::atan2(u.s, (u.c + u.s * sb) / cb);
    for (std::size_t i = 0; i < corr.k.size() && i < corr.orders.size(); ++i) {
      const double nt = corr.orders[i] * t0;
      u.s -= corr.k[i] * std::sin(nt);
      u.c -= corr.k[i] * std::cos(nt);
    }
  }
  return {u.s, (u.c + u.s * sb) / cb};
}

double corrected_angle(const SinCosCorrection& corr, double s, double c) {
  const SinCos u = correct_sincos(corr, s, c);
  return wrap_2pi(std::atan2(u.s, u.c));
}

double sum_difference_angle(const SinCosCorrection& corr, double s, double c) {
  const SinCos u = remove_offsets_and_gain(corr, s, c);
  const double sigma = 0.5 * corr.beta + 0.25 * kPi;  // Hanselman eq. 12
  const double vs = u.s + u.c;                        // eq. 11: 2 cos(sigma) sin(t + sigma)
  const double vc = u.s - u.c;                        //         -2 sin(sigma) cos(t + sigma)
  return wrap_2pi(std::atan2(vs / (2.0 * std::cos(sigma)), vc / (-2.0 * std::sin(sigma))) - sigma);
}

TrackingObserver::TrackingObserver(const TrackingObserverConfig& config) : config_(config) {
  if (!(config_.omega_n > 0.0) || !(config_.zeta > 0.0) || !(config_.sample_period > 0.0)) {
    throw std::invalid_argument("TrackingObserverConfig: omega_n (" + std::to_string(config_.omega_n) +
                                " rad/s), zeta (" + std::to_string(config_.zeta) + ") and sample_period (" +
                                std::to_string(config_.sample_period) + " s) must all be > 0");
  }
  const double wh = config_.omega_n * config_.sample_period;
  const double zeta = config_.zeta;
  const double d = std::exp(-2.0 * zeta * wh);  // product of the two discrete poles
  double sum = 0.0;                             // sum of the two discrete poles
  if (zeta < 1.0) {
    sum = 2.0 * std::exp(-zeta * wh) * std::cos(wh * std::sqrt(1.0 - zeta * zeta));
  } else {
    sum = 2.0 * std::exp(-zeta * wh) * std::cosh(wh * std::sqrt(zeta * zeta - 1.0));
  }
  g_ = 1.0 - d;
  k_ = 1.0 + d - sum;
}

double TrackingObserver::update(const SinCos& sc) {
  if (!state_.started) {
    state_.started = true;
    state_.phi = std::atan2(sc.s, sc.c);
    state_.omega = 0.0;
    return angle();
  }
  const double h = config_.sample_period;
  const double phi_pred = state_.phi + h * state_.omega;
  const double e = rd_error_signal(sc, phi_pred);
  state_.phi = phi_pred + g_ * e;
  state_.omega += k_ / h * e;
  return angle();
}

}  // namespace resolver
