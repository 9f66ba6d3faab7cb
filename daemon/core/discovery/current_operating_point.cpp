#include "daemon/core/discovery/current_operating_point.h"

#include <array>
#include <cmath>

#include <Eigen/Dense>

namespace resolver {

namespace {

constexpr std::array<int, 4> kRippleOrders = {1, 2, 6, 12};
static_assert(CurrentOperatingPointFit::kColumns == 1 + 2 * static_cast<int>(kRippleOrders.size()));
using Columns = Eigen::Matrix<double, CurrentOperatingPointFit::kColumns, 1>;
using Normal = Eigen::Matrix<double, CurrentOperatingPointFit::kColumns, CurrentOperatingPointFit::kColumns>;

Columns columns_at(double theta_e) {
  Columns x;
  x(0) = 1.0;
  for (std::size_t k = 0; k < kRippleOrders.size(); ++k) {
    const double a = kRippleOrders[k] * theta_e;
    x(static_cast<Eigen::Index>(1 + 2 * k)) = std::cos(a);
    x(static_cast<Eigen::Index>(2 + 2 * k)) = std::sin(a);
  }
  return x;
}

/// Smallest eigenvalue of the per-sample normal matrix for which the constant is taken
/// from the fit: over even coverage the matrix is diag(1, 1/2, ...), so 0.05 leaves an
/// order of magnitude of margin; below it some ripple order is not told from the constant
/// and the fit would amplify the noise into it.
constexpr double kMinEigenvalue = 0.05;

}  // namespace

void CurrentOperatingPointFit::add(double theta_e, double i_d, double i_q) {
  const Columns x = columns_at(theta_e);
  ata_.selfadjointView<Eigen::Lower>().rankUpdate(x);
  atb_.col(0) += x * i_d;
  atb_.col(1) += x * i_q;
  ++n_;
}

CurrentOperatingPoint CurrentOperatingPointFit::result() const {
  CurrentOperatingPoint out;
  if (n_ == 0) return out;
  const auto n = static_cast<double>(n_);
  // Row 0 of the sums is the plain sums of i_d and i_q (column 0 is 1).
  out.i_d = atb_(0, 0) / n;
  out.i_q = atb_(0, 1) / n;
  const Normal normal = Normal(ata_.selfadjointView<Eigen::Lower>()) / n;
  const Eigen::SelfAdjointEigenSolver<Normal> eig(normal, Eigen::EigenvaluesOnly);
  if (eig.info() != Eigen::Success || eig.eigenvalues()(0) < kMinEigenvalue) return out;
  const Eigen::Matrix<double, CurrentOperatingPointFit::kColumns, 2> coef = normal.ldlt().solve(atb_ / n);
  out.i_d = coef(0, 0);
  out.i_q = coef(0, 1);
  out.ripple_separated = true;
  return out;
}

}  // namespace resolver
