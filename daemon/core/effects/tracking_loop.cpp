#include "daemon/core/effects/tracking_loop.h"

#include <complex>

namespace resolver {

int tracking_loop_substeps(const TrackingLoopConfig& config, double duration) {
  if (!config.active() || duration <= 0.0) return 1;
  const double n = std::ceil(config.omega_n * duration / TrackingLoopConfig::kMaxOmegaNStep);
  return n < 1.0 ? 1 : static_cast<int>(n);
}

namespace {
struct Derivative {
  double dphi;
  double domega;
};

Derivative loop_derivative(const TrackingLoopConfig& c, const SinCos& sc, double phi, double omega) {
  const double e = rd_error_signal(sc, phi);
  return {omega + 2.0 * c.zeta * c.omega_n * e, c.omega_n * c.omega_n * e};
}
}  // namespace

void TrackingLoop::rk4_step(const SinCos& at_start, const SinCos& at_mid, const SinCos& at_end, double h) {
  const double phi = state_.phi;
  const double omega = state_.omega;
  const Derivative k1 = loop_derivative(config_, at_start, phi, omega);
  const Derivative k2 = loop_derivative(config_, at_mid, phi + 0.5 * h * k1.dphi, omega + 0.5 * h * k1.domega);
  const Derivative k3 = loop_derivative(config_, at_mid, phi + 0.5 * h * k2.dphi, omega + 0.5 * h * k2.domega);
  const Derivative k4 = loop_derivative(config_, at_end, phi + h * k3.dphi, omega + h * k3.domega);
  state_.phi = phi + h / 6.0 * (k1.dphi + 2.0 * k2.dphi + 2.0 * k3.dphi + k4.dphi);
  state_.omega = omega + h / 6.0 * (k1.domega + 2.0 * k2.domega + 2.0 * k3.domega + k4.domega);
}

namespace {
std::complex<double> closed_loop(const TrackingLoopConfig& c, double omega) {
  const std::complex<double> s(0.0, omega);
  const double wn = c.omega_n;
  const std::complex<double> num = 2.0 * c.zeta * wn * s + wn * wn;
  return num / (s * s + num);
}
}  // namespace

double tracking_loop_gain(const TrackingLoopConfig& config, double omega) {
  if (!config.active()) return 1.0;
  return std::abs(closed_loop(config, omega));
}

double tracking_loop_phase(const TrackingLoopConfig& config, double omega) {
  if (!config.active()) return 0.0;
  return std::arg(closed_loop(config, omega));
}

}  // namespace resolver
