#include "daemon/core/estimation/sincos_least_squares.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "daemon/core/angles.h"

namespace resolver {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Jacobian of g at x by central differences, step 1e-6 (1 + |x_j|): the
// conversions are smooth and x is O(1) after scaling, so the truncation error
// (~h^2 |g'''|) is ~1e-12 and the rounding error ~1e-16/h ~ 1e-10 relative.
template <typename G>
Eigen::MatrixXd numeric_jacobian(const G& g, const Eigen::VectorXd& x) {
  const Eigen::VectorXd g0 = g(x);
  Eigen::MatrixXd j(g0.size(), x.size());
  for (Eigen::Index k = 0; k < x.size(); ++k) {
    const double h = 1e-6 * (1.0 + std::abs(x(k)));
    Eigen::VectorXd xp = x, xm = x;
    xp(k) += h;
    xm(k) -= h;
    j.col(k) = (g(xp) - g(xm)) / (2.0 * h);
  }
  return j;
}

// Residual variance of a weighted LS with p parameters (see the header):
// sigma^2 = RSS / W * n_eff / (n_eff - p), n_eff = W^2 / W2.
double residual_variance(double rss, double w, double w2, int p) {
  const double n_eff = w * w / w2;
  if (n_eff <= p) return kNaN;
  return std::max(rss, 0.0) / w * n_eff / (n_eff - p);
}

Estimate est(const Eigen::VectorXd& v, const Eigen::MatrixXd& cov, Eigen::Index i, double unit = 1.0) {
  const double var = cov(i, i);
  return {v(i) * unit, (var >= 0.0 ? std::sqrt(var) : kNaN) * unit};
}

}  // namespace

SinCosLeastSquares::SinCosLeastSquares(const SinCosLsConfig& config) : config_(config) {
  if (!(config_.forgetting > 0.0 && config_.forgetting <= 1.0)) {
    throw std::invalid_argument("SinCosLsConfig.forgetting must be in (0, 1], got " +
                                std::to_string(config_.forgetting));
  }
  for (std::size_t i = 0; i < config_.harmonics.size(); ++i) {
    const int n = config_.harmonics[i];
    if (n < 2) {
      throw std::invalid_argument("SinCosLsConfig.harmonics: order " + std::to_string(n) +
                                  " must be >= 2 (order 1 is the fundamental, K_0 is in the offsets)");
    }
    if (std::count(config_.harmonics.begin(), config_.harmonics.end(), n) > 1) {
      throw std::invalid_argument("SinCosLsConfig.harmonics: order " + std::to_string(n) + " is repeated");
    }
  }
  reset();
}

void SinCosLeastSquares::reset() {
  state_ = SinCosLsState{};
  const int p = ref_params();
  state_.ref_m = Eigen::MatrixXd::Zero(p, p);
  state_.ref_bs = Eigen::VectorXd::Zero(p);
  state_.ref_bc = Eigen::VectorXd::Zero(p);
}

void SinCosLeastSquares::set_scale(double s, double c) {
  if (state_.scale > 0.0) return;
  const double r = std::hypot(s, c);
  state_.scale = config_.scale > 0.0 ? config_.scale : (r > 0.0 ? r : 1.0);
}

void SinCosLeastSquares::add(double s, double c) {
  set_scale(s, c);
  const double u = s / state_.scale;
  const double v = c / state_.scale;
  Eigen::Matrix<double, 5, 1> z;
  z << u * u, u * v, v * v, u, v;
  const double lambda = config_.forgetting;
  state_.conic_m = lambda * state_.conic_m + z * z.transpose();
  state_.conic_b = lambda * state_.conic_b + z;
  state_.conic_w = lambda * state_.conic_w + 1.0;
  state_.conic_w2 = lambda * lambda * state_.conic_w2 + 1.0;
  ++state_.seen_conic;
}

void SinCosLeastSquares::add(double s, double c, double theta_ref) {
  add(s, c);
  const double u = s / state_.scale;
  const double v = c / state_.scale;
  const int p = ref_params();
  Eigen::VectorXd phi(p);
  phi(0) = 1.0;
  phi(1) = std::sin(theta_ref);
  phi(2) = std::cos(theta_ref);
  for (std::size_t h = 0; h < config_.harmonics.size(); ++h) {
    const double nt = config_.harmonics[h] * theta_ref;
    const auto i = static_cast<Eigen::Index>(3 + 2 * h);
    phi(i) = std::sin(nt);
    phi(i + 1) = std::cos(nt);
  }
  const double lambda = config_.forgetting;
  state_.ref_m = lambda * state_.ref_m + phi * phi.transpose();
  state_.ref_bs = lambda * state_.ref_bs + u * phi;
  state_.ref_bc = lambda * state_.ref_bc + v * phi;
  state_.ref_ss = lambda * state_.ref_ss + u * u;
  state_.ref_cc = lambda * state_.ref_cc + v * v;
  state_.ref_w = lambda * state_.ref_w + 1.0;
  state_.ref_w2 = lambda * lambda * state_.ref_w2 + 1.0;
  ++state_.seen_reference;
}

std::optional<SinCosFit> SinCosLeastSquares::solve() const {
  if (state_.seen_reference >= config_.min_samples) {
    if (auto fit = solve_reference()) return fit;
  }
  return solve_conic();
}

std::optional<SinCosFit> SinCosLeastSquares::solve_reference() const {
  const int p = ref_params();
  if (state_.seen_reference < std::max<std::int64_t>(config_.min_samples, p + 1)) return std::nullopt;
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(state_.ref_m);
  if (ldlt.info() != Eigen::Success || !ldlt.isPositive()) return std::nullopt;
  // Reject a rank-deficient M (angles not spread): smallest pivot vs largest.
  const Eigen::VectorXd d = ldlt.vectorD();
  if (d.minCoeff() <= 1e-9 * d.maxCoeff()) return std::nullopt;
  const Eigen::VectorXd xs = ldlt.solve(state_.ref_bs);
  const Eigen::VectorXd xc = ldlt.solve(state_.ref_bc);
  const double w = state_.ref_w, w2 = state_.ref_w2;
  const double rss_s = state_.ref_ss - xs.dot(state_.ref_bs);
  const double rss_c = state_.ref_cc - xc.dot(state_.ref_bc);
  const double var_s = residual_variance(rss_s, w, w2, p);
  const double var_c = residual_variance(rss_c, w, w2, p);
  const Eigen::MatrixXd m_inv = ldlt.solve(Eigen::MatrixXd::Identity(p, p)) * (w2 / w);

  // Stacked coefficients and their block-diagonal covariance.
  Eigen::VectorXd x(2 * p);
  x << xs, xc;
  Eigen::MatrixXd cov = Eigen::MatrixXd::Zero(2 * p, 2 * p);
  cov.topLeftCorner(p, p) = var_s * m_inv;
  cov.bottomRightCorner(p, p) = var_c * m_inv;

  const std::vector<int>& orders = config_.harmonics;
  const bool with_delta = config_.fit_reference_offset;
  // Conversion (see the header): g(x) = (A, alpha, beta, o_s, o_c, delta, K_n...).
  const auto convert = [&orders, p, with_delta](const Eigen::VectorXd& xx) {
    const double s0 = xx(0), s1 = xx(1), s2 = xx(2);
    const double c0 = xx(p), c2 = xx(p + 1), c1 = xx(p + 2);
    const double a = with_delta ? std::hypot(s1, s2) : s1;
    const double delta = with_delta ? std::atan2(s2, s1) : 0.0;
    const double b = std::hypot(c1, c2);
    const double gamma = std::atan2(-c2, c1);
    Eigen::VectorXd g(6 + static_cast<Eigen::Index>(orders.size()));
    g(0) = a;
    g(1) = b / a - 1.0;
    g(2) = wrap_pi(gamma - delta);
    g(3) = s0 / a;
    g(4) = c0 / a;
    g(5) = delta;
    for (std::size_t h = 0; h < orders.size(); ++h) {
      const double nd = orders[h] * delta;
      const auto i = static_cast<Eigen::Index>(3 + 2 * h);
      const double ks = (xx(i) * std::cos(nd) + xx(i + 1) * std::sin(nd)) / a;
      const double kc = (xx(p + i + 1) * std::cos(nd) - xx(p + i) * std::sin(nd)) / b;
      g(6 + static_cast<Eigen::Index>(h)) = (a * a * ks + b * b * kc) / (a * a + b * b);
    }
    return g;
  };
  const Eigen::VectorXd g = convert(x);
  if (!(g(0) > 0.0) || !g.allFinite()) return std::nullopt;
  const Eigen::MatrixXd jac = numeric_jacobian(convert, x);
  const Eigen::MatrixXd gcov = jac * cov * jac.transpose();

  SinCosFit fit;
  fit.method = SinCosFitMethod::kReference;
  fit.amplitude = est(g, gcov, 0, state_.scale);
  fit.alpha = est(g, gcov, 1);
  fit.beta = est(g, gcov, 2);
  fit.o_s = est(g, gcov, 3);
  fit.o_c = est(g, gcov, 4);
  fit.reference_offset = with_delta ? est(g, gcov, 5) : Estimate{0.0, kNaN};
  fit.harmonic_orders = orders;
  for (std::size_t h = 0; h < orders.size(); ++h) fit.k.push_back(est(g, gcov, 6 + static_cast<Eigen::Index>(h)));
  fit.samples = w;
  fit.samples_seen = state_.seen_reference;
  fit.residual_rms = std::sqrt(std::max(rss_s + rss_c, 0.0) / (2.0 * w)) * state_.scale;
  return fit;
}

std::optional<SinCosFit> SinCosLeastSquares::solve_conic() const {
  constexpr int kP = 5;
  if (state_.seen_conic < std::max<std::int64_t>(config_.min_samples, kP + 1)) return std::nullopt;
  const Eigen::LDLT<Eigen::Matrix<double, 5, 5>> ldlt(state_.conic_m);
  if (ldlt.info() != Eigen::Success || !ldlt.isPositive()) return std::nullopt;
  const Eigen::Matrix<double, 5, 1> d = ldlt.vectorD();
  if (d.minCoeff() <= 1e-12 * d.maxCoeff()) return std::nullopt;
  const Eigen::VectorXd x = ldlt.solve(state_.conic_b);
  const double w = state_.conic_w, w2 = state_.conic_w2;
  const double rss = w - x.dot(state_.conic_b);  // sum w (z^T p - 1)^2 at the optimum
  const double var = residual_variance(rss, w, w2, kP);
  const Eigen::MatrixXd cov = var * (w2 / w) * ldlt.solve(Eigen::Matrix<double, 5, 5>::Identity());

  // Conversion (see the header): g(p) = (A, alpha, beta, o_s, o_c, k); NaN when not an ellipse.
  const auto convert = [](const Eigen::VectorXd& pp) {
    const double a = pp(0), b = pp(1), e = pp(2), dd = pp(3), f = pp(4);
    Eigen::VectorXd g = Eigen::VectorXd::Constant(6, kNaN);
    const double det = 4.0 * a * e - b * b;  // > 0 for an ellipse
    if (!(det > 0.0)) return g;
    // [2a b; b 2e] (S0, C0) = (-d, -f) by Cramer's rule.
    const double s0 = (-dd * 2.0 * e + f * b) / det;
    const double c0 = (-f * 2.0 * a + dd * b) / det;
    const double k = 1.0 + a * s0 * s0 + b * s0 * c0 + e * c0 * c0;
    const double pq = a / k, qq = b / k, rq = e / k;
    if (!(pq > 0.0 && rq > 0.0)) return g;
    const double sin_beta = qq / (2.0 * std::sqrt(pq * rq));
    const double cos_beta = std::sqrt(std::max(1.0 - sin_beta * sin_beta, 0.0));
    const double amp = 1.0 / (std::sqrt(pq) * cos_beta);
    g(0) = amp;
    g(1) = std::sqrt(pq / rq) - 1.0;
    g(2) = std::asin(sin_beta);
    g(3) = s0 / amp;
    g(4) = c0 / amp;
    g(5) = k;
    return g;
  };
  const Eigen::VectorXd g = convert(x);
  if (!g.allFinite() || !(g(0) > 0.0)) return std::nullopt;
  const Eigen::MatrixXd jac = numeric_jacobian(convert, x);
  if (!jac.allFinite()) return std::nullopt;
  const Eigen::MatrixXd gcov = jac * cov * jac.transpose();

  SinCosFit fit;
  fit.method = SinCosFitMethod::kConic;
  fit.amplitude = est(g, gcov, 0, state_.scale);
  fit.alpha = est(g, gcov, 1);
  fit.beta = est(g, gcov, 2);
  fit.o_s = est(g, gcov, 3);
  fit.o_c = est(g, gcov, 4);
  fit.reference_offset = {0.0, kNaN};
  fit.samples = w;
  fit.samples_seen = state_.seen_conic;
  // Algebraic residual r = z^T p - 1 = k (rho^2/A^2 - 1) ~ 2 k d_rho / A near the
  // fitted curve, so the radial residual is r A / (2 k) [scaled units].
  fit.residual_rms = std::sqrt(std::max(rss, 0.0) / w) * g(0) / (2.0 * g(5)) * state_.scale;
  return fit;
}

}  // namespace resolver
