#include "daemon/core/effects/tracking_loop.h"

#include <array>
#include <complex>
#include <stdexcept>

#include "daemon/core/effects/effect.h"
#include "daemon/core/effects/param_set.h"

namespace resolver {

int tracking_loop_substeps(const TrackingLoopParams& config, double duration) {
  if (!tracking_loop_active(config) || duration <= 0.0) return 1;
  const double n = std::ceil(config["omega_n"] * duration / kTrackingLoopMaxOmegaNStep);
  return n < 1.0 ? 1 : static_cast<int>(n);
}

namespace {
struct Derivative {
  double dphi;
  double domega;
};

Derivative loop_derivative(const TrackingLoopParams& c, const SinCos& sc, double phi, double omega) {
  const double e = rd_error_signal(sc, phi);
  const double omega_n = c["omega_n"];
  return {omega + 2.0 * c["zeta"] * omega_n * e, omega_n * omega_n * e};
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

std::complex<double> tracking_loop_response(const TrackingLoopParams& config, double omega) {
  if (!tracking_loop_active(config)) return {1.0, 0.0};
  // H(j w) = (a + ib) / (c + ib) with a = wn^2, b = 2 zeta wn w, c = wn^2 - w^2, divided
  // out by hand: std::complex's division (__divdc3, with its inf and NaN cases) was a
  // tenth of a fit's time (every row's R/D columns); c^2 + b^2 > 0 for zeta > 0 (its
  // range starts at 0.01).
  const double wn = config["omega_n"];
  const double a = wn * wn, b = 2.0 * config["zeta"] * wn * omega, c = a - omega * omega;
  const double inv = 1.0 / (c * c + b * b);
  return {(a * c + b * b) * inv, (b * c - a * b) * inv};
}

std::complex<double> tracking_loop_response(const TrackingLoopParams& config, double omega, double omega_rate) {
  if (omega_rate == 0.0 || !tracking_loop_active(config)) return tracking_loop_response(config, omega);
  // H = N / D, N = wn^2 + j b w, D = wn^2 - w^2 + j b w (b = 2 zeta wn); N'' = 0, D'' = -2:
  // H' = (N' - H D') / D, H'' = (2 H - 2 H' D') / D. Division as a product with 1 / D
  // (std::complex's __divdc3 was 18 % of a fit's time with a loop in the model).
  const double wn = config["omega_n"];
  const double b = 2.0 * config["zeta"] * wn;
  const double dr = wn * wn - omega * omega, di = b * omega;
  const double inv = 1.0 / (dr * dr + di * di);
  const auto over_d = [&](double re, double im) {
    return std::complex<double>((re * dr + im * di) * inv, (im * dr - re * di) * inv);
  };
  const std::complex<double> h = over_d(wn * wn, b * omega);
  const std::complex<double> d1(-2.0 * omega, b);
  const std::complex<double> n1 = std::complex<double>(0.0, b) - h * d1;
  const std::complex<double> h1 = over_d(n1.real(), n1.imag());
  const std::complex<double> n2 = 2.0 * h - 2.0 * h1 * d1;
  const std::complex<double> h2 = over_d(n2.real(), n2.imag());
  // h - j (rate / 2) h2
  return {h.real() + 0.5 * omega_rate * h2.imag(), h.imag() - 0.5 * omega_rate * h2.real()};
}

double tracking_loop_gain(const TrackingLoopParams& config, double omega) {
  return std::abs(tracking_loop_response(config, omega));
}

double tracking_loop_phase(const TrackingLoopParams& config, double omega) {
  return std::arg(tracking_loop_response(config, omega));
}

}  // namespace resolver

// ---- registry unit ------------------------------------------------------------
namespace resolver {
namespace {

class TrackingLoopEffect final : public BasicEffect {
 public:
  TrackingLoopEffect()
      : BasicEffect({"tracking_loop", "type-II R/D loop: error ripple filtered by H(s), lag a/omega_n^2 under acceleration",
                     "Hanselman II.A, Hwang Fig. 2; tracking_loop.h",
                     "the R/D converter's closed loop filters the error harmonics: the ripple of the R/D angle changes "
                     "in amplitude and phase with speed, the sin/cos signals do not"},
                    kTrackingLoopParams, EffectStage::kConverter) {}
  [[nodiscard]] bool needs_speed_change() const override { return true; }
  [[nodiscard]] Needs identifiable_with() const override { return Needs::kSpeedChangeOrSinCos; }
  [[nodiscard]] bool active(Values v) const override { return tracking_loop_active(TrackingLoopParams(v)); }
  void validate(Values v) const override {
    const TrackingLoopParams p(v);
    if (tracking_loop_active(p) && !(p["zeta"] > 0.0)) throw std::invalid_argument("tracking_loop.zeta must be > 0");
  }
  void converter(Values v, ConverterSpec& spec) const override {
    spec.loop = TrackingLoopParams(v);
  }
  [[nodiscard]] bool shapes_basis() const override { return true; }
  void configure_basis(const SignatureRow& /*row*/, Values v, BasisTransform& t) const override {
    t.loop = TrackingLoopParams(v);
  }
  // Both parameters act through the basis (every other effect's rd harmonics),
  // so they have no columns of their own; the fit differentiates numerically.
  // The loop's own term: a type-II loop lags a constant acceleration a by a / omega_n^2.
  [[nodiscard]] bool linear_in_params() const override { return false; }
  void contribution(const SignatureRow& row, const AngleBasis& /*b*/, Values v, SignalValues& out) const override {
    const double omega_n = TrackingLoopParams(v)["omega_n"];
    if (omega_n > 0.0) out.rd += row.accel / (omega_n * omega_n);
  }
};

}  // namespace

const Effect& tracking_loop_effect() {
  static const TrackingLoopEffect effect;
  return effect;
}

}  // namespace resolver
