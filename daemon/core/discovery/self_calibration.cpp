#include "daemon/core/discovery/self_calibration.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

#include "daemon/core/angles.h"

namespace resolver {

namespace {
constexpr std::size_t kMinWindowSamples = 200;
constexpr double kWindowRevolutions = 2.0;
constexpr int kMaxOrder = 8;
constexpr double kGapPeriods = 3.0;

int nyquist_order(double omega, double dt) {
  if (!(omega > 0.0) || !(dt > 0.0)) return kMaxOrder;
  return std::clamp(static_cast<int>(std::floor(0.9 * kPi / (omega * dt))), 1, kMaxOrder);
}

void fit_window(std::span<const double> t, std::span<const double> angle, std::span<const double> wrapped,
                std::size_t i0, std::size_t i1, double dt, SelfCalibration& out) {
  const double turned = std::abs(angle[i1 - 1] - angle[i0]);
  if (turned < kTwoPi) {
    out.unusable += static_cast<std::int64_t>(i1 - i0);
    return;
  }
  const double ta = t[i0], tb = t[i1 - 1];
  const double mid = 0.5 * (ta + tb), half = std::max(0.5 * (tb - ta), 1e-12);
  const int order = nyquist_order(turned / std::max(tb - ta, 1e-12), dt);
  const int k = 4 + 2 * order;
  Eigen::MatrixXd m = Eigen::MatrixXd::Zero(k, k);
  Eigen::VectorXd b = Eigen::VectorXd::Zero(k);
  Eigen::VectorXd x(k);
  const double base = angle[i0];
  auto fill = [&](std::size_t i) {
    const double tau = (t[i] - mid) / half;
    x[0] = 1.0;
    x[1] = tau;
    x[2] = tau * tau;
    x[3] = tau * tau * tau;
    for (int h = 1; h <= order; ++h) {
      x[2 + 2 * h] = std::sin(h * wrapped[i]);
      x[3 + 2 * h] = std::cos(h * wrapped[i]);
    }
  };
  for (std::size_t i = i0; i < i1; ++i) {
    fill(i);
    m.selfadjointView<Eigen::Lower>().rankUpdate(x);
    b += x * (angle[i] - base);
  }
  m = m.selfadjointView<Eigen::Lower>();
  const Eigen::VectorXd c = m.completeOrthogonalDecomposition().solve(b);
  for (std::size_t i = i0; i < i1; ++i) {
    const double tau = (t[i] - mid) / half;
    out.ideal[i] = base + c[0] + tau * (c[1] + tau * (c[2] + tau * c[3]));
    out.usable[i] = true;
  }
  ++out.windows;
}

}  // namespace

SelfCalibration self_calibrate(std::span<const double> t, std::span<const double> angle,
                               std::span<const double> wrapped, std::span<const MotionSample> motion, double dt) {
  const std::size_t n = t.size();
  SelfCalibration out;
  out.ideal.assign(angle.begin(), angle.end());
  out.usable.assign(n, false);
  std::size_t i = 0;
  while (i < n) {
    if (!motion[i].moving) {
      ++i;
      continue;
    }
    // One stretch: moving, one direction, contiguous in time.
    std::size_t j = i + 1;
    while (j < n && motion[j].moving && motion[j].direction == motion[i].direction &&
           t[j] - t[j - 1] <= kGapPeriods * dt) {
      ++j;
    }
    // Windows of >= 2 revolutions and >= 200 samples; a short tail joins the last.
    std::size_t w0 = i;
    while (w0 < j) {
      std::size_t w1 = w0 + 1;
      while (w1 < j && (w1 - w0 < kMinWindowSamples || std::abs(angle[w1 - 1] - angle[w0]) < kWindowRevolutions * kTwoPi)) {
        ++w1;
      }
      if (j - w1 < kMinWindowSamples || std::abs(angle[j - 1] - angle[w1 - 1]) < kWindowRevolutions * kTwoPi) w1 = j;
      fit_window(t, angle, wrapped, w0, w1, dt, out);
      w0 = w1;
    }
    i = j;
  }
  return out;
}

}  // namespace resolver
