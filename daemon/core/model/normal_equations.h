// Sufficient statistics of a least-squares problem: the normal equations
// M = sum x x', b = sum x y, y'y and the row count, for one group of signals.
// A fit, its residual sum of squares for any coefficient vector, and the fit of any
// subset of the columns all follow from them without a second look at the rows:
//   RSS(c) = y'y - 2 c'b + c'Mc.
// Two accumulations of disjoint rows add (merge), so windows, folds, logs and
// machines combine exactly.
//
// Rows are buffered and added a block at a time: one matrix product per block is
// several times faster than a rank-1 update per row. flush() adds them and frees the
// buffer (kBlock rows of every column: about as large as M itself), so statistics kept
// after their pass (a long log's chunks, issue 23) hold only their sums.
#pragma once

#include <Eigen/Dense>
#include <cstdint>

namespace resolver {

class NormalEquations {
 public:
  NormalEquations() = default;
  explicit NormalEquations(int columns);

  /// Adds one row x (length columns()) with target y and weight 1.
  void add(const Eigen::Ref<const Eigen::VectorXd>& x, double y);
  /// Adds the buffered rows and frees the buffer (the next add() takes it again); the
  /// const readers m(), b() add them lazily without freeing.
  void flush();
  /// Adds another accumulation of the same columns (exact merge).
  void merge(const NormalEquations& other);

  [[nodiscard]] int columns() const { return static_cast<int>(b_.size()); }
  [[nodiscard]] const Eigen::MatrixXd& m() const;
  [[nodiscard]] const Eigen::VectorXd& b() const;
  [[nodiscard]] double yy() const { return yy_; }
  [[nodiscard]] std::int64_t n() const { return n_; }
  /// Residual sum of squares of coefficients c (>= 0).
  [[nodiscard]] double rss(const Eigen::VectorXd& c) const;

  /// Restores accumulated sums (a statistics file, a merge): m must be symmetric.
  void set(Eigen::MatrixXd m, Eigen::VectorXd b, double yy, std::int64_t n);

 private:
  static constexpr int kBlock = 64;
  void flush_const() const;
  mutable Eigen::MatrixXd m_;
  mutable Eigen::VectorXd b_;
  mutable Eigen::MatrixXd rows_;
  mutable Eigen::VectorXd y_;
  mutable int used_ = 0;
  double yy_ = 0.0;
  std::int64_t n_ = 0;
};

}  // namespace resolver
