#include "daemon/core/estimation/tracking_loop_fit.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>

#include "daemon/core/angles.h"

namespace resolver {
namespace {

using cd = std::complex<double>;
constexpr double kInf = std::numeric_limits<double>::infinity();

void validate(const TrackingLoopFitConfig& c) {
  if (c.order < 1 || c.order > 16) {
    throw std::invalid_argument("TrackingLoopFitConfig.order must be in 1..16, got " + std::to_string(c.order));
  }
  if (c.max_iterations < 1) {
    throw std::invalid_argument("TrackingLoopFitConfig.max_iterations must be >= 1, got " +
                                std::to_string(c.max_iterations));
  }
  if (!(c.max_relative_stderr > 0.0)) {
    throw std::invalid_argument("TrackingLoopFitConfig.max_relative_stderr must be > 0, got " +
                                std::to_string(c.max_relative_stderr));
  }
}

void validate(const RippleBinConfig& c) {
  if (c.max_order < 1 || c.max_order > 16) {
    throw std::invalid_argument("RippleBinConfig.max_order must be in 1..16, got " + std::to_string(c.max_order));
  }
  if (c.order < 1 || c.order > c.max_order) {
    throw std::invalid_argument("RippleBinConfig.order must be in 1..max_order (" + std::to_string(c.max_order) +
                                "), got " + std::to_string(c.order));
  }
  if (!(c.speed_tolerance > 0.0)) {
    throw std::invalid_argument("RippleBinConfig.speed_tolerance must be > 0, got " +
                                std::to_string(c.speed_tolerance));
  }
  if (!(c.settle_s >= 0.0)) {
    throw std::invalid_argument("RippleBinConfig.settle_s must be >= 0 [s], got " + std::to_string(c.settle_s));
  }
  if (c.min_revolutions < 1) {
    throw std::invalid_argument("RippleBinConfig.min_revolutions must be >= 1, got " +
                                std::to_string(c.min_revolutions));
  }
  if (c.max_revolutions < 0 || (c.max_revolutions > 0 && c.max_revolutions < c.min_revolutions)) {
    throw std::invalid_argument("RippleBinConfig.max_revolutions must be 0 (no split) or >= min_revolutions, got " +
                                std::to_string(c.max_revolutions));
  }
}

// H(s) and its derivatives with respect to omega_n and zeta at s = j omega.
struct LoopResponse {
  cd h, d_wn, d_zeta;
};

LoopResponse loop_response(double wn, double zeta, double omega) {
  const cd s(0.0, omega);
  const cd num = 2.0 * zeta * wn * s + wn * wn;
  const cd den = s * s + num;
  const cd s2_den2 = s * s / (den * den);
  // dH/dp = N'(p) (D - N) / D^2 = N'(p) s^2 / D^2 since D' = N'.
  return {num / den, (2.0 * zeta * s + 2.0 * wn) * s2_den2, 2.0 * wn * s * s2_den2};
}

enum class StaticMode : std::uint8_t { kExact, kPrior, kFree };

// The weighted residuals and their Jacobian in q = (ln wn, ln zeta[, Re C, Im C]).
struct Problem {
  std::span<const RippleObservation> obs;
  int order = 2;
  StaticMode mode = StaticMode::kExact;
  cd c0;                // given C_static (exact or prior mean)
  double sigma_c = 0.0; // prior std

  [[nodiscard]] Eigen::Index params() const { return mode == StaticMode::kExact ? 2 : 4; }
  [[nodiscard]] Eigen::Index residuals() const {
    return 2 * static_cast<Eigen::Index>(obs.size()) + (mode == StaticMode::kPrior ? 2 : 0);
  }
  [[nodiscard]] cd coefficient(const Eigen::VectorXd& q) const {
    return mode == StaticMode::kExact ? c0 : cd(q(2), q(3));
  }

  void evaluate(const Eigen::VectorXd& q, Eigen::VectorXd& r, Eigen::MatrixXd* jac) const {
    const double wn = std::exp(q(0));
    const double zeta = std::exp(q(1));
    const cd c = coefficient(q);
    r.resize(residuals());
    if (jac != nullptr) jac->setZero(residuals(), params());
    Eigen::Index row = 0;
    for (const auto& o : obs) {
      const LoopResponse lr = loop_response(wn, zeta, order * o.omega_e);
      const cd res = (c * lr.h - o.measured) / o.std_error;
      r(row) = res.real();
      r(row + 1) = res.imag();
      if (jac != nullptr) {
        const cd d0 = c * lr.d_wn * wn / o.std_error;
        const cd d1 = c * lr.d_zeta * zeta / o.std_error;
        (*jac)(row, 0) = d0.real();
        (*jac)(row + 1, 0) = d0.imag();
        (*jac)(row, 1) = d1.real();
        (*jac)(row + 1, 1) = d1.imag();
        if (mode != StaticMode::kExact) {
          const cd dre = lr.h / o.std_error;
          const cd dim = cd(0.0, 1.0) * lr.h / o.std_error;
          (*jac)(row, 2) = dre.real();
          (*jac)(row + 1, 2) = dre.imag();
          (*jac)(row, 3) = dim.real();
          (*jac)(row + 1, 3) = dim.imag();
        }
      }
      row += 2;
    }
    if (mode == StaticMode::kPrior) {
      const cd res = (c - c0) / sigma_c;
      r(row) = res.real();
      r(row + 1) = res.imag();
      if (jac != nullptr) {
        (*jac)(row, 2) = 1.0 / sigma_c;
        (*jac)(row + 1, 3) = 1.0 / sigma_c;
      }
    }
  }

  // Grid start: cost at (wn, zeta) with C_static solved linearly when fitted.
  [[nodiscard]] double grid_cost(double wn, double zeta, cd& c_out) const {
    cd c = c0;
    if (mode != StaticMode::kExact) {
      cd num = mode == StaticMode::kPrior ? c0 / (sigma_c * sigma_c) : cd(0.0, 0.0);
      double den = mode == StaticMode::kPrior ? 1.0 / (sigma_c * sigma_c) : 0.0;
      for (const auto& o : obs) {
        const cd h = loop_response(wn, zeta, order * o.omega_e).h;
        const double w = 1.0 / (o.std_error * o.std_error);
        num += w * std::conj(h) * o.measured;
        den += w * std::norm(h);
      }
      if (den > 0.0) c = num / den;
    }
    c_out = c;
    double cost = 0.0;
    for (const auto& o : obs) {
      const cd h = loop_response(wn, zeta, order * o.omega_e).h;
      cost += std::norm((c * h - o.measured) / o.std_error);
    }
    if (mode == StaticMode::kPrior) cost += std::norm((c - c0) / sigma_c);
    return cost;
  }
};

TrackingLoopEstimate failed(TrackingLoopEstimate e, std::string why) {
  e.ok = false;
  e.message = std::move(why);
  return e;
}

/// The problem of the inputs, its mode from the static ripple's std error.
Problem make_problem(const StaticRipple& static_ripple, std::span<const RippleObservation> observations, int order) {
  Problem p;
  p.obs = observations;
  p.order = order;
  p.c0 = static_ripple.value;
  p.sigma_c = static_ripple.std_error;
  p.mode = static_ripple.std_error == 0.0 ? StaticMode::kExact
           : std::isinf(static_ripple.std_error) ? StaticMode::kFree
                                                  : StaticMode::kPrior;
  return p;
}

/// The observed ripple frequencies n |omega_e| [rad/s]: the lowest non-zero one and the
/// highest; or why an observation cannot be used.
struct ObservedFrequencies {
  double lo = kInf, hi = 0.0;
  std::string problem;  ///< empty when every observation is usable
};

ObservedFrequencies observed_frequencies(std::span<const RippleObservation> observations, int order) {
  ObservedFrequencies f;
  for (std::size_t k = 0; k < observations.size(); ++k) {
    const auto& o = observations[k];
    if (!std::isfinite(o.omega_e) || !std::isfinite(o.measured.real()) || !std::isfinite(o.measured.imag()) ||
        !(o.std_error > 0.0) || !std::isfinite(o.std_error)) {
      f.problem = "observation " + std::to_string(k) +
                  ": omega_e and measured must be finite and std_error finite and > 0";
      return f;
    }
    const double freq = std::abs(order * o.omega_e);
    if (freq > 0.0) f.lo = std::min(f.lo, freq);
    f.hi = std::max(f.hi, freq);
  }
  return f;
}

/// The starting point: the best of a coarse log-spaced grid of (omega_n, zeta) around the
/// observed frequencies, C_static solved linearly at each point when it is fitted.
Eigen::VectorXd grid_start(const Problem& p, double f_min, double f_max) {
  constexpr int kGridWn = 81, kGridZeta = 41;
  const double wn_lo = std::log(0.05 * f_min), wn_hi = std::log(20.0 * f_max);
  const double z_lo = std::log(0.05), z_hi = std::log(5.0);
  double best = kInf;
  Eigen::VectorXd q = Eigen::VectorXd::Zero(p.params());
  for (int i = 0; i < kGridWn; ++i) {
    const double lwn = wn_lo + (wn_hi - wn_lo) * i / (kGridWn - 1);
    for (int j = 0; j < kGridZeta; ++j) {
      const double lz = z_lo + (z_hi - z_lo) * j / (kGridZeta - 1);
      cd c;
      const double cost = p.grid_cost(std::exp(lwn), std::exp(lz), c);
      if (cost < best) {
        best = cost;
        q(0) = lwn;
        q(1) = lz;
        if (p.params() == 4) {
          q(2) = c.real();
          q(3) = c.imag();
        }
      }
    }
  }
  return q;
}

/// Where Levenberg-Marquardt stopped: the parameters q, the Jacobian there and the cost.
struct Minimum {
  Eigen::VectorXd q;
  Eigen::MatrixXd jac;
  double cost = 0.0;
  int iterations = 0;
  bool converged = false;
};

/// Levenberg-Marquardt (Marquardt's diagonal scaling) from q.
Minimum levenberg_marquardt(const Problem& p, Eigen::VectorXd q, int max_iterations) {
  Eigen::VectorXd r, r_new;
  Eigen::MatrixXd jac;
  p.evaluate(q, r, &jac);
  double cost = r.squaredNorm();
  double lambda = 1e-3;
  bool converged = false;
  int it = 0;
  for (; it < max_iterations && !converged; ++it) {
    const Eigen::MatrixXd a = jac.transpose() * jac;
    const Eigen::VectorXd g = jac.transpose() * r;
    for (;;) {
      Eigen::MatrixXd damped = a;
      for (Eigen::Index d = 0; d < damped.rows(); ++d) damped(d, d) += lambda * std::max(a(d, d), 1e-300);
      const Eigen::VectorXd step = damped.ldlt().solve(-g);
      const Eigen::VectorXd q_new = q + step;
      p.evaluate(q_new, r_new, nullptr);
      const double cost_new = r_new.squaredNorm();
      if (std::isfinite(cost_new) && cost_new <= cost) {
        const double drop = cost - cost_new;
        q = q_new;
        cost = cost_new;
        p.evaluate(q, r, &jac);
        lambda = std::max(lambda * 0.1, 1e-12);
        if (drop <= 1e-12 * cost + 1e-300) converged = true;
        break;
      }
      lambda *= 10.0;
      if (lambda > 1e12) {  // no descent left: a (numerical) minimum
        converged = true;
        break;
      }
    }
  }
  return {std::move(q), std::move(jac), cost, it, converged};
}

/// Covariance: (J^T J)^-1 x max(1, reduced chi^2), mapped from ln-parameters to
/// (omega_n, zeta[, Re C, Im C]); nullopt when the normal matrix is singular.
std::optional<Eigen::MatrixXd> parameter_covariance(const Problem& p, const Eigen::MatrixXd& jac, double omega_n,
                                                    double zeta, double reduced_chi2) {
  const Eigen::MatrixXd a = jac.transpose() * jac;
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(a);
  if (eig.info() != Eigen::Success || !(eig.eigenvalues().minCoeff() > 1e-13 * eig.eigenvalues().maxCoeff())) {
    return std::nullopt;
  }
  const Eigen::MatrixXd cov_q = eig.eigenvectors() * eig.eigenvalues().cwiseInverse().asDiagonal() *
                                eig.eigenvectors().transpose() * std::max(1.0, reduced_chi2);
  Eigen::VectorXd scale = Eigen::VectorXd::Ones(p.params());
  scale(0) = omega_n;
  scale(1) = zeta;
  return Eigen::MatrixXd(scale.asDiagonal() * cov_q * scale.asDiagonal());
}

}  // namespace

TrackingLoopEstimate fit_tracking_loop(std::complex<double> static_coefficient,
                                       std::span<const RippleObservation> observations,
                                       const TrackingLoopFitConfig& config) {
  return fit_tracking_loop(StaticRipple{static_coefficient, 0.0}, observations, config);
}

TrackingLoopEstimate fit_tracking_loop(const StaticRipple& static_ripple,
                                       std::span<const RippleObservation> observations,
                                       const TrackingLoopFitConfig& config) {
  validate(config);
  TrackingLoopEstimate est;
  est.order = config.order;
  est.static_coefficient = static_ripple.value;
  est.omega_n = std::numeric_limits<double>::quiet_NaN();
  est.zeta = std::numeric_limits<double>::quiet_NaN();

  const Problem p = make_problem(static_ripple, observations, config.order);
  if (!(static_ripple.std_error >= 0.0) || !std::isfinite(static_ripple.value.real()) ||
      !std::isfinite(static_ripple.value.imag())) {
    return failed(est, "static ripple: value must be finite and std_error >= 0 (0 exact, inf free)");
  }
  if (p.mode != StaticMode::kFree && std::abs(p.c0) == 0.0) {
    return failed(est, "static ripple is zero: the loop cannot be seen through a zero ripple");
  }
  const ObservedFrequencies f = observed_frequencies(observations, config.order);
  if (!f.problem.empty()) return failed(est, f.problem);
  est.dof = static_cast<int>(p.residuals() - p.params());
  if (est.dof < 1) {
    return failed(est, std::to_string(observations.size()) + " observations give " + std::to_string(est.dof) +
                           " degrees of freedom: need at least " +
                           (p.mode == StaticMode::kFree ? "3" : "2") + " speeds");
  }
  if (!(f.hi > 0.0)) return failed(est, "all observations at standstill: the ripple frequency is zero");

  const Minimum m = levenberg_marquardt(p, grid_start(p, f.lo, f.hi), config.max_iterations);
  est.iterations = m.iterations;
  est.omega_n = std::exp(m.q(0));
  est.zeta = std::exp(m.q(1));
  est.static_coefficient = p.coefficient(m.q);
  est.chi2 = m.cost;
  est.residual = m.cost / est.dof;
  if (!m.converged) return failed(est, "Levenberg-Marquardt did not converge in max_iterations");

  const std::optional<Eigen::MatrixXd> cov = parameter_covariance(p, m.jac, est.omega_n, est.zeta, est.residual);
  if (!cov) return failed(est, "singular normal matrix: (omega_n, zeta) not identifiable from these speeds");
  est.covariance.topLeftCorner(p.params(), p.params()) = *cov;
  est.omega_n_stderr = std::sqrt((*cov)(0, 0));
  est.zeta_stderr = std::sqrt((*cov)(1, 1));
  est.static_stderr = p.params() == 4 ? std::sqrt(0.5 * ((*cov)(2, 2) + (*cov)(3, 3))) : 0.0;
  if (!std::isfinite(est.omega_n) || !std::isfinite(est.zeta) || !std::isfinite(est.omega_n_stderr)) {
    return failed(est, "non-finite estimate");
  }
  if (est.omega_n_stderr > config.max_relative_stderr * est.omega_n) {
    return failed(est, "omega_n not identifiable: relative std error " +
                           std::to_string(est.omega_n_stderr / est.omega_n) +
                           " (the ripple frequencies must reach omega_n)");
  }
  est.ok = true;
  return est;
}

RipplePrediction predict_ripple(const TrackingLoopEstimate& estimate, double omega_e) {
  const LoopResponse lr = loop_response(estimate.omega_n, estimate.zeta, estimate.order * omega_e);
  const cd c = estimate.static_coefficient;
  const cd grad[4] = {c * lr.d_wn, c * lr.d_zeta, lr.h, cd(0.0, 1.0) * lr.h};
  Eigen::Matrix<double, 2, 4> g;
  for (int k = 0; k < 4; ++k) {
    g(0, k) = grad[k].real();
    g(1, k) = grad[k].imag();
  }
  const Eigen::Matrix2d cov = g * estimate.covariance * g.transpose();
  return {c * lr.h, std::sqrt(std::max(cov(0, 0), 0.0)), std::sqrt(std::max(cov(1, 1), 0.0))};
}

double predict_ripple_error(const TrackingLoopEstimate& estimate, double theta, double omega_e) {
  const cd c = predict_ripple(estimate, omega_e).value;
  return std::imag(c * std::polar(1.0, estimate.order * theta));
}

std::optional<RippleObservation> measure_ripple(std::span<const double> t, std::span<const double> theta_ref,
                                                std::span<const double> theta_rd, const RippleBinConfig& config) {
  validate(config);
  const std::size_t n_all = t.size();
  if (theta_ref.size() != n_all || theta_rd.size() != n_all || n_all < 2) return std::nullopt;
  // Unwrap the reference and keep the longest prefix of whole revolutions.
  std::vector<double> u(n_all);
  u[0] = theta_ref[0];
  for (std::size_t i = 1; i < n_all; ++i) u[i] = u[i - 1] + wrap_pi(theta_ref[i] - theta_ref[i - 1]);
  const double revs = std::floor(std::abs(u[n_all - 1] - u[0]) / kTwoPi);
  if (revs < 1.0) return std::nullopt;
  std::size_t n = n_all;
  for (std::size_t i = 1; i < n_all; ++i) {
    if (std::abs(u[i] - u[0]) >= revs * kTwoPi) {
      n = i;
      break;
    }
  }
  const int h = config.max_order;
  const Eigen::Index np = 2 * h + 1;
  if (n < static_cast<std::size_t>(4 * h + 2)) return std::nullopt;

  // Normal equations of eps on [1, sin k theta, cos k theta].
  Eigen::MatrixXd m = Eigen::MatrixXd::Zero(np, np);
  Eigen::VectorXd b = Eigen::VectorXd::Zero(np);
  Eigen::VectorXd row(np);
  const auto fill = [&](std::size_t i) {
    row(0) = 1.0;
    for (int k = 1; k <= h; ++k) {
      row(2 * k - 1) = std::sin(k * u[i]);
      row(2 * k) = std::cos(k * u[i]);
    }
  };
  std::vector<double> eps(n);
  double t_mean = 0.0, u_mean = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    eps[i] = wrap_pi(theta_ref[i] - theta_rd[i]);
    fill(i);
    m.selfadjointView<Eigen::Lower>().rankUpdate(row);
    b += eps[i] * row;
    t_mean += t[i];
    u_mean += u[i];
  }
  m = m.selfadjointView<Eigen::Lower>();
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(m);
  if (ldlt.info() != Eigen::Success || !ldlt.isPositive()) return std::nullopt;
  const Eigen::VectorXd x = ldlt.solve(b);
  const double nd = static_cast<double>(n);
  t_mean /= nd;
  u_mean /= nd;
  double rss = 0.0, stt = 0.0, stu = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    fill(i);
    const double e = eps[i] - row.dot(x);
    rss += e * e;
    stt += (t[i] - t_mean) * (t[i] - t_mean);
    stu += (t[i] - t_mean) * (u[i] - u_mean);
  }
  if (!(stt > 0.0)) return std::nullopt;
  const double sigma2 = rss / (nd - static_cast<double>(np));
  const Eigen::MatrixXd inv = ldlt.solve(Eigen::MatrixXd::Identity(np, np));
  const Eigen::Index ia = 2 * config.order - 1, ib = 2 * config.order;
  RippleObservation o;
  o.omega_e = stu / stt;
  o.measured = {x(ia), x(ib)};
  o.std_error = std::sqrt(sigma2 * 0.5 * (inv(ia, ia) + inv(ib, ib)));
  o.revolutions = revs;
  o.t_begin = t[0];
  o.t_end = t[n - 1];
  o.residual_rms = std::sqrt(rss / nd);
  if (!(o.std_error > 0.0)) {
    // An exact fit (noise-free, unquantized data): report the rounding floor instead of 0.
    o.std_error = std::numeric_limits<double>::epsilon() * std::max(std::abs(o.measured), 1e-300);
  }
  return o;
}

std::vector<RippleObservation> ripple_observations(std::span<const double> t, std::span<const double> theta_ref,
                                                   std::span<const double> theta_rd, const RippleBinConfig& config) {
  validate(config);
  std::vector<RippleObservation> out;
  const std::size_t n = t.size();
  if (theta_ref.size() != n || theta_rd.size() != n || n < 2) return out;
  std::vector<double> u(n);
  u[0] = theta_ref[0];
  for (std::size_t i = 1; i < n; ++i) u[i] = u[i - 1] + wrap_pi(theta_ref[i] - theta_ref[i - 1]);
  // Revolution boundaries (sample indices) and each revolution's mean speed.
  std::vector<std::size_t> edge{0};
  for (std::size_t i = 1; i < n; ++i) {
    if (std::abs(u[i] - u[edge.back()]) >= kTwoPi) edge.push_back(i);
  }
  const std::size_t revs = edge.size() - 1;
  std::vector<double> speed(revs);
  for (std::size_t r = 0; r < revs; ++r) {
    speed[r] = (u[edge[r + 1]] - u[edge[r]]) / (t[edge[r + 1]] - t[edge[r]]);
  }
  const auto measure_bin = [&](std::size_t r0, std::size_t r1) {  // revolutions r0..r1-1
    const std::size_t i0 = edge[r0], len = edge[r1] - i0 + 1;
    if (auto o = measure_ripple(t.subspan(i0, len), theta_ref.subspan(i0, len), theta_rd.subspan(i0, len), config)) {
      out.push_back(*o);
    }
  };
  std::size_t g = 0;
  while (g < revs) {
    std::size_t e = g + 1;  // group: revolutions g..e-1 within tolerance of revolution g
    while (e < revs && std::abs(speed[e] - speed[g]) <= config.speed_tolerance * std::abs(speed[g])) ++e;
    std::size_t r0 = g;
    while (r0 < e && t[edge[r0]] < t[edge[g]] + config.settle_s) ++r0;
    const auto min_r = static_cast<std::size_t>(config.min_revolutions);
    const std::size_t chunk = config.max_revolutions > 0 ? static_cast<std::size_t>(config.max_revolutions) : e;
    for (std::size_t s = r0; s < e && e - s >= min_r; s += chunk) measure_bin(s, std::min(s + chunk, e));
    g = e;
  }
  return out;
}

}  // namespace resolver
