#include "daemon/core/model/loop_correction.h"

#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>
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
/// Trailing orders of a node smaller than this [rad] are not kept.
constexpr double kKeepAbove = 1e-15;

/// The order of FFT bin j (0 .. N/2 - 1, then negative; the Nyquist bin is left out).
int order_of(int j) { return j <= kGridPoints / 2 ? j : j - kGridPoints; }

}  // namespace

double LoopCorrectionSeries::at(const AngleBasis& basis) const {
  double out = 0.0;
  for (std::size_t n = 0; n < c_cos.size(); ++n) {
    const int k = static_cast<int>(n);
    out += c_cos[n] * basis.env_cos(k) + c_sin[n] * basis.env_sin(k);
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
  // order k changes over zeta wn / k in speed (its resonance's width).
  spacing_ = kNodeWidth * std::min(loop["zeta"], 1.0) * loop["omega_n"] / (2.0 * highest);
}

LoopCorrectionSeries LoopCorrection::solve(double omega) const {
  LoopCorrectionSeries out;
  if (!active_) return out;
  constexpr int n = kGridPoints;
  Eigen::FFT<double> fft;
  fft.SetFlag(Eigen::FFT<double>::Unscaled);
  Spectrum h(n), grid(n), e_hat, d0(n), d(n), n_hat;
  for (int j = 0; j < n; ++j) {
    const int k = order_of(j);
    h[static_cast<std::size_t>(j)] = j == n / 2 ? 0.0 : tracking_loop_response(loop_, k * omega);
    grid[static_cast<std::size_t>(j)] = e_[static_cast<std::size_t>(j)];
  }
  fft.fwd(e_hat, grid);
  for (std::size_t j = 0; j < static_cast<std::size_t>(n); ++j) d0[j] = -(1.0 - h[j]) * e_hat[j] / double{n};
  d = d0;
  out.converged = false;
  for (int it = 0; it < kMaxIterations; ++it) {
    fft.inv(grid, d);  // D on the grid (unscaled inverse of coefficients: the values)
    for (std::size_t j = 0; j < static_cast<std::size_t>(n); ++j) {
      const double dj = grid[j].real();
      grid[j] = (1.0 + r_[j]) * std::sin(dj) - dj;
    }
    fft.fwd(n_hat, grid);
    double moved = 0.0;
    for (std::size_t j = 0; j < static_cast<std::size_t>(n); ++j) {
      n_hat[j] /= double{n};
      const std::complex<double> next = d0[j] - h[j] * n_hat[j];
      moved = std::max(moved, std::abs(next - d[j]));
      d[j] = next;
    }
    if (moved < kTolerance) {
      out.converged = true;
      break;
    }
  }
  // c = -H N(D) (header), as cos / sin coefficients of the real series.
  out.c_cos.assign(n / 2, 0.0);
  out.c_sin.assign(n / 2, 0.0);
  for (int k = 0; k < n / 2; ++k) {
    const std::complex<double> c = -h[static_cast<std::size_t>(k)] * n_hat[static_cast<std::size_t>(k)];
    out.c_cos[static_cast<std::size_t>(k)] = k == 0 ? c.real() : 2.0 * c.real();
    out.c_sin[static_cast<std::size_t>(k)] = k == 0 ? 0.0 : -2.0 * c.imag();
  }
  std::size_t keep = out.c_cos.size();
  while (keep > 0 && std::abs(out.c_cos[keep - 1]) + std::abs(out.c_sin[keep - 1]) < kKeepAbove) --keep;
  out.c_cos.resize(keep);
  out.c_sin.resize(keep);
  return out;
}

const LoopCorrectionSeries& LoopCorrection::node(std::int64_t i) const {
  auto it = nodes_.find(i);
  if (it == nodes_.end()) it = nodes_.emplace(i, solve(static_cast<double>(i) * spacing_)).first;
  return it->second;
}

double LoopCorrection::at(const AngleBasis& basis) const {
  if (!active_) return 0.0;
  const double x = basis.row().omega / spacing_;
  if (!std::isfinite(x)) return 0.0;
  const double below = std::floor(x);
  const double f = x - below;
  const auto i = static_cast<std::int64_t>(below);
  const double a = node(i).at(basis);
  return f == 0.0 ? a : (1.0 - f) * a + f * node(i + 1).at(basis);
}

}  // namespace resolver
