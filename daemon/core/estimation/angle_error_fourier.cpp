#include "daemon/core/estimation/angle_error_fourier.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "daemon/core/angles.h"

namespace resolver {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

void validate(const AngleFourierConfig& c) {
  if (c.max_order < 1) {
    throw std::invalid_argument("AngleFourierConfig.max_order must be >= 1, got " + std::to_string(c.max_order));
  }
  if (!(c.forgetting > 0.0 && c.forgetting <= 1.0)) {
    throw std::invalid_argument("AngleFourierConfig.forgetting must be in (0, 1], got " +
                                std::to_string(c.forgetting));
  }
  if (c.poly_order < 0 || c.poly_order > 6) {
    throw std::invalid_argument("AngleFourierConfig.poly_order must be in 0..6, got " +
                                std::to_string(c.poly_order));
  }
}

// Fills the 2N harmonic regressors (sin n theta, cos n theta, n = 1..N) at offset `at`.
void harmonic_row(double theta, int n_max, Eigen::Ref<Eigen::VectorXd> row, Eigen::Index at, double sign) {
  for (int n = 1; n <= n_max; ++n) {
    const double nt = n * theta;
    row(at + 2 * (n - 1)) = sign * std::sin(nt);
    row(at + 2 * (n - 1) + 1) = sign * std::cos(nt);
  }
}

// Fills fit.a, fit.b from coefficients x (harmonics from index `at`, stored as
// (a_n, b_n) pairs with covariance cov) and maps them to catalog parameters.
void fill_harmonics(AngleErrorFit& fit, const Eigen::VectorXd& x, const Eigen::MatrixXd& cov, Eigen::Index at,
                    int n_max) {
  fit.max_order = n_max;
  fit.a.assign(static_cast<std::size_t>(n_max) + 1, Estimate{0.0, kNaN});
  fit.b.assign(static_cast<std::size_t>(n_max) + 1, Estimate{0.0, kNaN});
  for (int n = 1; n <= n_max; ++n) {
    const Eigen::Index i = at + 2 * (n - 1);
    fit.a[static_cast<std::size_t>(n)] = {x(i), std::sqrt(std::max(cov(i, i), 0.0))};
    fit.b[static_cast<std::size_t>(n)] = {x(i + 1), std::sqrt(std::max(cov(i + 1, i + 1), 0.0))};
  }
  fit.o_c = fit.a[1];
  fit.o_s = {-fit.b[1].value, fit.b[1].std_error};
  if (n_max >= 2) {
    const double a2 = fit.a[2].value;
    // alpha = 2 a_2 / (1 - a_2) (exact for alpha alone), d alpha / d a_2 = 2 / (1 - a_2)^2.
    fit.alpha = {2.0 * a2 / (1.0 - a2), 2.0 / ((1.0 - a2) * (1.0 - a2)) * fit.a[2].std_error};
    fit.beta = {2.0 * fit.b[2].value, 2.0 * fit.b[2].std_error};
  } else {
    fit.alpha = {kNaN, kNaN};
    fit.beta = {kNaN, kNaN};
  }
}

}  // namespace

double AngleErrorFit::eps(double theta) const {
  double e = std::isfinite(a0.value) ? a0.value : 0.0;
  for (int n = 1; n <= max_order; ++n) {
    const double nt = n * theta;
    e += a[static_cast<std::size_t>(n)].value * std::sin(nt) + b[static_cast<std::size_t>(n)].value * std::cos(nt);
  }
  return e;
}

double AngleErrorFit::compensate(double theta_rd) const { return wrap_2pi(theta_rd + eps(theta_rd)); }

AngleErrorFourier::AngleErrorFourier(const AngleFourierConfig& config) : config_(config) {
  validate(config_);
  reset();
}

void AngleErrorFourier::reset() {
  const int p = 1 + 2 * config_.max_order;
  m_ = Eigen::MatrixXd::Zero(p, p);
  b_ = Eigen::VectorXd::Zero(p);
  yy_ = w_ = w2_ = 0.0;
  seen_ = 0;
}

void AngleErrorFourier::add(double theta_ref, double theta_rd) {
  const double eps = wrap_pi(theta_ref - theta_rd);
  const int p = 1 + 2 * config_.max_order;
  Eigen::VectorXd phi(p);
  phi(0) = 1.0;
  harmonic_row(theta_rd, config_.max_order, phi, 1, 1.0);
  const double lambda = config_.forgetting;
  m_ = lambda * m_ + phi * phi.transpose();
  b_ = lambda * b_ + eps * phi;
  yy_ = lambda * yy_ + eps * eps;
  w_ = lambda * w_ + 1.0;
  w2_ = lambda * lambda * w2_ + 1.0;
  ++seen_;
}

std::optional<AngleErrorFit> AngleErrorFourier::solve() const {
  const int p = 1 + 2 * config_.max_order;
  if (seen_ < std::max<std::int64_t>(config_.min_samples, p + 1)) return std::nullopt;
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(m_);
  if (ldlt.info() != Eigen::Success || !ldlt.isPositive()) return std::nullopt;
  const Eigen::VectorXd d = ldlt.vectorD();
  if (d.minCoeff() <= 1e-9 * d.maxCoeff()) return std::nullopt;
  const Eigen::VectorXd x = ldlt.solve(b_);
  const double rss = std::max(yy_ - x.dot(b_), 0.0);
  // Weighted residual variance and covariance as in sincos_least_squares.h.
  const double n_eff = w_ * w_ / w2_;
  const double var = n_eff > p ? rss / w_ * n_eff / (n_eff - p) : kNaN;
  const Eigen::MatrixXd cov = var * (w2_ / w_) * ldlt.solve(Eigen::MatrixXd::Identity(p, p));
  AngleErrorFit fit;
  fit.a0 = {x(0), std::sqrt(std::max(cov(0, 0), 0.0))};
  fill_harmonics(fit, x, cov, 1, config_.max_order);
  fit.samples = w_;
  fit.residual_rms = std::sqrt(rss / w_);
  return fit;
}

std::optional<AngleErrorFit> fit_error_smooth_angle(std::span<const double> t, std::span<const double> theta_rd,
                                                    const AngleFourierConfig& config) {
  validate(config);
  if (t.size() != theta_rd.size() || t.empty()) return std::nullopt;
  // Unwrap, then keep the longest prefix spanning whole revolutions.
  std::vector<double> th(theta_rd.size());
  AngleUnwrapper unwrap;
  for (std::size_t i = 0; i < th.size(); ++i) th[i] = unwrap.update(theta_rd[i]);
  std::size_t n = 0;
  double revs = 0.0;
  {
    const double total = std::abs(th.back() - th.front());
    revs = std::floor(total / kTwoPi);
    if (revs < 1.0) return std::nullopt;
    const double span = revs * kTwoPi;
    while (n < th.size() && std::abs(th[n] - th.front()) < span) ++n;
  }
  const int n_poly = config.poly_order + 1;
  const int p = n_poly + 2 * config.max_order;
  if (static_cast<std::int64_t>(n) < std::max<std::int64_t>(config.min_samples, p + 1)) return std::nullopt;

  // Scaled time tau in [-1, 1] keeps the polynomial columns O(1); the angle is
  // taken relative to its first sample so the constant stays small.
  const double t0 = t[0], t1 = t[n - 1];
  const double half = 0.5 * (t1 - t0);
  if (!(half > 0.0)) return std::nullopt;
  const double mid = 0.5 * (t0 + t1);
  Eigen::MatrixXd jm(static_cast<Eigen::Index>(n), p);
  Eigen::VectorXd y(static_cast<Eigen::Index>(n));
  for (std::size_t i = 0; i < n; ++i) {
    const auto r = static_cast<Eigen::Index>(i);
    const double tau = (t[i] - mid) / half;
    double pw = 1.0;
    for (int j = 0; j < n_poly; ++j) {
      jm(r, j) = pw;
      pw *= tau;
    }
    // theta_rd = poly - eps  =>  the harmonic columns carry a minus sign.
    Eigen::VectorXd row(2 * config.max_order);
    harmonic_row(wrap_2pi(th[i]), config.max_order, row, 0, -1.0);
    jm.row(r).tail(2 * config.max_order) = row.transpose();
    y(r) = th[i] - th.front();
  }
  // Column-pivoting QR on the (well scaled) design: no squared condition number.
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(jm);
  if (qr.rank() < p) return std::nullopt;
  const Eigen::VectorXd x = qr.solve(y);
  const Eigen::VectorXd res = y - jm * x;
  const double rss = res.squaredNorm();
  const double var = rss / static_cast<double>(static_cast<std::int64_t>(n) - p);
  const Eigen::MatrixXd jtj = jm.transpose() * jm;
  const Eigen::MatrixXd cov = var * jtj.ldlt().solve(Eigen::MatrixXd::Identity(p, p));

  AngleErrorFit fit;
  fit.a0 = {0.0, kNaN};
  fill_harmonics(fit, x, cov, n_poly, config.max_order);
  fit.samples = static_cast<double>(n);
  fit.residual_rms = std::sqrt(rss / static_cast<double>(n));
  fit.revolutions = revs;
  return fit;
}

}  // namespace resolver
