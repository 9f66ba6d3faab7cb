#include "daemon/core/model/loop_correction.h"

#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
#include <numbers>
#include <Eigen/Dense>
#include <unsupported/Eigen/FFT>

namespace resolver {

namespace {

using Spectrum = std::vector<std::complex<double>>;

/// The harmonic balance stops when no coefficient of D moves by more than this [rad]
/// (far below any floor; the contraction makes the rest smaller still) ...
constexpr double kTolerance = 1e-15;
/// ... or after this many iterations (|H| |r| >= 1: a loop whose gain swings that much
/// has no small-ripple steady state; the last iterate is kept and flagged).
constexpr int kMaxIterations = 200;
/// A coefficient of e or r below this [rad or 1] is not counted in the orders the
/// correction reaches (it modulates nothing above 1e-12 rad).
constexpr double kSignificant = 1e-9;
/// The iteration is taken as diverging when a coefficient moves by this much [rad].
constexpr double kDiverged = 1.0;
/// Newton's method (newton below) stops when no grid value of D moves by more than this
/// [rad] (it converges quadratically: the step after is at rounding).
constexpr double kNewtonTolerance = 1e-13;

/// The order of FFT bin j (0 .. N/2 - 1, then negative; the Nyquist bin is left out).
int order_of(int j) { return j <= kGridPoints / 2 ? j : j - kGridPoints; }

}  // namespace

double LoopCorrectionSeries::at(const AngleBasis& basis, double lag) const {
  double out = 0.0;
  for (std::size_t i = 0; i < k.size(); ++i) {
    const double c = basis.env_cos(k[i]), s = basis.env_sin(k[i]);
    out += (c_cos[i] + lag * g_cos[i]) * c + (c_sin[i] + lag * g_sin[i]) * s;
  }
  return out;
}

LoopCorrection::LoopCorrection(const EnvelopeSeries& series, const TrackingLoopParams& loop) : loop_(loop) {
  int highest = 0;
  for (std::size_t i = 0; i < series.k.size(); ++i) {
    const double size = std::abs(series.e_cos[i]) + std::abs(series.e_sin[i]) + std::abs(series.r_cos[i]) +
                        std::abs(series.r_sin[i]);
    if (series.k[i] > 0 && size > kSignificant) highest = std::max(highest, series.k[i]);
  }
  active_ = tracking_loop_active(loop) && highest > 0;
  if (!active_) return;
  for (int j = 0; j < kGridPoints; ++j) {
    const double phi = 2.0 * std::numbers::pi * j / kGridPoints;
    double e = 0.0, r = 0.0;
    for (std::size_t i = 0; i < series.k.size(); ++i) {
      const double c = std::cos(series.k[i] * phi), s = std::sin(series.k[i] * phi);
      e += series.e_cos[i] * c + series.e_sin[i] * s;
      r += series.r_cos[i] * c + series.r_sin[i] * s;
    }
    e_[static_cast<std::size_t>(j)] = e;
    r_[static_cast<std::size_t>(j)] = r;
  }
  // The correction reaches orders up to twice the series' (products of e and r); H of
  // order k changes over zeta wn / k in speed (its resonance's width). Below zeta 0.1 the
  // spacing stays that of 0.1: the catalog's zeta 0.01 would put 10x more nodes on a speed
  // range (a ramp over wn: 160,000 nodes, seconds and ~100 MB per fit point); there the
  // interpolation error at the resonance grows to (10 kNodeWidth)^2 / 8 = 5e-3 of the
  // correction.
  spacing_ = kNodeWidth * std::clamp(loop["zeta"], 0.1, 1.0) * loop["omega_n"] / (2.0 * highest);
}

namespace {

/// Iterates the balance x = x0 - H [F(x)] (F pointwise on the grid: F(j, x_j); H diagonal in
/// the orders) from x0 until no coefficient moves by kTolerance. Returns whether it converged.
template <typename Pointwise>
bool balance(Eigen::FFT<double>& fft, const Spectrum& h, const Spectrum& x0, Pointwise&& pointwise, Spectrum& x) {
  const std::size_t n = h.size();
  Spectrum grid(n), f_hat;
  x = x0;
  for (int it = 0; it < kMaxIterations; ++it) {
    fft.inv(grid, x);  // the values on the grid (unscaled inverse of coefficients)
    for (std::size_t j = 0; j < n; ++j) grid[j] = pointwise(j, grid[j].real());
    fft.fwd(f_hat, grid);
    // Squared moves (std::abs is a hypot: it was 45 % of a lightly damped loop's fit).
    double moved2 = 0.0;
    for (std::size_t j = 0; j < n; ++j) {
      const std::complex<double> next = x0[j] - h[j] * f_hat[j] / static_cast<double>(n);
      moved2 = std::max(moved2, std::norm(next - x[j]));
      x[j] = next;
    }
    if (moved2 < kTolerance * kTolerance) return true;
    // A tracking error moving by a radian per iteration is diverging (|H| |r| > 1 near a
    // resonance): Newton's turn, without 200 iterations on ever larger arguments of sin.
    if (!(moved2 < kDiverged * kDiverged)) return false;
  }
  return false;
}

/// Newton's method on the grid for the same balance, D = D0 - H[N(D)] with N(D) = (1 + r)
/// sin D - D, where the iteration above does not contract: its linearisation is
/// -H[N'(D) .], whose spectral radius exceeds 1 when a lightly damped loop's resonance
/// amplifies the orders the radius ripple couples (zeta 0.02 and a 15 % gain error at a
/// twentieth of wn: the iteration diverged to 1e186 while the simulated loop settled within
/// 6e-5 rad of the linear filter's prediction). With C the circulant matrix of H's impulse
/// response, each step solves (I + C diag(N'(D))) dD = -(D - D0 + C N(D)) densely
/// (kGridPoints unknowns: a few ms, only at such nodes). On success `d` holds D's
/// coefficients and `delta` dD/dL, the acceleration lag's derivative (header), from the
/// same matrix at the solution. Returns false when it does not converge either (no
/// periodic steady state: the loop loses lock there).
bool newton(Eigen::FFT<double>& fft, const Spectrum& h, const Spectrum& d0, const std::array<double, kGridPoints>& r,
            Spectrum& d, Spectrum& delta) {
  constexpr int n = kGridPoints;
  constexpr int kMaxSteps = 30;
  Spectrum grid;
  fft.inv(grid, h);  // the impulse response (times n: the inverse is unscaled)
  Eigen::MatrixXd circulant(n, n);
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) circulant(i, j) = grid[static_cast<std::size_t>((i - j + n) % n)].real() / n;
  }
  fft.inv(grid, d0);
  Eigen::VectorXd base(n), x(n);
  for (int j = 0; j < n; ++j) base[j] = grid[static_cast<std::size_t>(j)].real();
  x = base;
  Eigen::VectorXd nonlinear(n), slope(n);
  Eigen::MatrixXd jacobian(n, n);
  bool converged = false;
  double last_size = std::numeric_limits<double>::infinity();
  for (int step = 0; step < kMaxSteps && !converged; ++step) {
    for (int j = 0; j < n; ++j) {
      const double one_plus_r = 1.0 + r[static_cast<std::size_t>(j)];
      nonlinear[j] = one_plus_r * std::sin(x[j]) - x[j];
      slope[j] = one_plus_r * std::cos(x[j]) - 1.0;
    }
    jacobian = circulant * slope.asDiagonal();
    jacobian.diagonal().array() += 1.0;
    const Eigen::VectorXd dx = jacobian.partialPivLu().solve(-(x - base + circulant * nonlinear));
    // No steady state near: a step of half a turn (the loop would slip a cycle), or one no
    // smaller than the last once past the start (where it converges, quadratically, each
    // step is far smaller than the last), ends it.
    const double size = dx.cwiseAbs().maxCoeff();
    if (!(size < std::numbers::pi) || (step >= 10 && size >= last_size)) return false;
    last_size = size;
    x += dx;
    converged = size < kNewtonTolerance;
  }
  if (!converged || x.cwiseAbs().maxCoeff() > std::numbers::pi) return false;
  for (int j = 0; j < n; ++j) slope[j] = (1.0 + r[static_cast<std::size_t>(j)]) * std::cos(x[j]) - 1.0;
  jacobian = circulant * slope.asDiagonal();
  jacobian.diagonal().array() += 1.0;
  const Eigen::VectorXd lag_slope = jacobian.partialPivLu().solve(Eigen::VectorXd::Ones(n));
  const auto to_spectrum = [&](const Eigen::VectorXd& values, Spectrum& out) {
    Spectrum g(static_cast<std::size_t>(n));
    for (int j = 0; j < n; ++j) g[static_cast<std::size_t>(j)] = values[j];
    fft.fwd(out, g);
    for (auto& v : out) v /= double{n};
  };
  to_spectrum(x, d);
  to_spectrum(lag_slope, delta);
  return true;
}

/// The real series (k >= 0: cos, sin) of the coefficients c and g into `out`, orders where
/// both are below kDropBelow left out.
void to_series(const Spectrum& c, const Spectrum& g, LoopCorrectionSeries& out) {
  const int half = static_cast<int>(c.size()) / 2;
  for (int k = 0; k < half; ++k) {
    const std::complex<double> a = c[static_cast<std::size_t>(k)], b = g[static_cast<std::size_t>(k)];
    const double w = k == 0 ? 1.0 : 2.0;
    const double cc = w * a.real(), cs = k == 0 ? 0.0 : -2.0 * a.imag();
    const double gc = w * b.real(), gs = k == 0 ? 0.0 : -2.0 * b.imag();
    if (std::abs(cc) + std::abs(cs) + std::abs(gc) + std::abs(gs) <= kDropBelow) continue;
    out.k.push_back(k);
    out.c_cos.push_back(cc);
    out.c_sin.push_back(cs);
    out.g_cos.push_back(gc);
    out.g_sin.push_back(gs);
  }
}

}  // namespace

LoopCorrectionSeries LoopCorrection::solve(double omega) const {
  LoopCorrectionSeries out;
  if (!active_) return out;
  constexpr int n = kGridPoints;
  constexpr auto un = static_cast<std::size_t>(n);
  Eigen::FFT<double> fft;
  fft.SetFlag(Eigen::FFT<double>::Unscaled);
  Spectrum h(un), grid(un), e_hat, d0(un), d;
  for (int j = 0; j < n; ++j) {
    h[static_cast<std::size_t>(j)] = j == n / 2 ? 0.0 : tracking_loop_response(loop_, order_of(j) * omega);
    grid[static_cast<std::size_t>(j)] = e_[static_cast<std::size_t>(j)];
  }
  fft.fwd(e_hat, grid);
  for (std::size_t j = 0; j < un; ++j) d0[j] = -(1.0 - h[j]) * e_hat[j] / double{n};
  // D = D0 - H[N(D)], N(D) = (1 + r) sin D - D pointwise on the grid.
  Spectrum delta;
  bool converged = balance(fft, h, d0, [&](std::size_t j, double dj) { return (1.0 + r_[j]) * std::sin(dj) - dj; }, d);
  if (converged) {
    // The acceleration lag L = a / wn^2 enters D0 as a constant: dD/dL = delta solves
    // delta = 1 - H[N'(D) delta], N'(D) = (1 + r) cos D - 1, and dc/dL = delta - 1.
    std::vector<double> slope(un);
    fft.inv(grid, d);
    for (std::size_t j = 0; j < un; ++j) slope[j] = (1.0 + r_[j]) * std::cos(grid[j].real()) - 1.0;
    Spectrum one(un, 0.0);
    one[0] = 1.0;
    converged = balance(fft, h, one, [&](std::size_t j, double x) { return slope[j] * x; }, delta);
  }
  if (!converged) converged = newton(fft, h, d0, r_, d, delta);
  out.converged = converged;
  // No steady state: the linear filter's prediction alone, flagged (the fit says so and
  // does not call the model explained), never a diverged iterate.
  if (!converged) return out;
  // c = -H N(D) = D - D0 (header).
  Spectrum c(un);
  for (std::size_t j = 0; j < un; ++j) c[j] = d[j] - d0[j];
  delta[0] -= 1.0;
  to_series(c, delta, out);
  return out;
}

const LoopCorrectionSeries& LoopCorrection::node(std::int64_t i) const {
  auto it = nodes_.find(i);
  if (it == nodes_.end()) it = nodes_.emplace(i, solve(static_cast<double>(i) * spacing_)).first;
  return it->second;
}

bool LoopCorrection::converged_at(double omega) const {
  const double x = omega / spacing_;
  if (!active_ || !std::isfinite(x)) return true;
  const auto i = static_cast<std::int64_t>(std::floor(x));
  return node(i).converged && (x == std::floor(x) || node(i + 1).converged);
}

double LoopCorrection::at(const AngleBasis& basis) const {
  if (!active_) return 0.0;
  const double x = basis.row().omega / spacing_;
  if (!std::isfinite(x)) return 0.0;
  const double below = std::floor(x);
  const double f = x - below;
  const auto i = static_cast<std::int64_t>(below);
  // The loop's lag behind a constant acceleration (tracking_loop.h): a / wn^2.
  const double lag = basis.row().accel / (loop_["omega_n"] * loop_["omega_n"]);
  const double a = node(i).at(basis, lag);
  return f == 0.0 ? a : (1.0 - f) * a + f * node(i + 1).at(basis, lag);
}

}  // namespace resolver
