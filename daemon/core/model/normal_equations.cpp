#include "daemon/core/model/normal_equations.h"

#include <algorithm>

namespace resolver {

NormalEquations::NormalEquations(int columns)
    : m_(Eigen::MatrixXd::Zero(columns, columns)), b_(Eigen::VectorXd::Zero(columns)) {}

void NormalEquations::add(const Eigen::Ref<const Eigen::VectorXd>& x, double y) {
  if (rows_.rows() == 0) {  // released by flush(): the buffer is only held while rows come
    rows_.resize(kBlock, columns());
    y_.resize(kBlock);
  }
  rows_.row(used_) = x.transpose();
  y_[used_] = y;
  yy_ += y * y;
  ++n_;
  if (++used_ == kBlock) flush_const();
}

void NormalEquations::flush_const() const {
  if (used_ == 0) return;
  const auto block = rows_.topRows(used_);
  m_.selfadjointView<Eigen::Lower>().rankUpdate(block.transpose());
  b_.noalias() += block.transpose() * y_.head(used_);
  used_ = 0;
  // rankUpdate fills the lower triangle: mirror it so m() is the whole matrix.
  m_.triangularView<Eigen::StrictlyUpper>() = m_.transpose();
}

void NormalEquations::flush() {
  flush_const();
  rows_.resize(0, 0);
  y_.resize(0);
}

const Eigen::MatrixXd& NormalEquations::m() const {
  flush_const();
  return m_;
}

const Eigen::VectorXd& NormalEquations::b() const {
  flush_const();
  return b_;
}

void NormalEquations::merge(const NormalEquations& other) {
  flush();
  m_ += other.m();
  b_ += other.b();
  yy_ += other.yy_;
  n_ += other.n_;
}

double NormalEquations::rss(const Eigen::VectorXd& c) const {
  if (c.size() == 0) return yy_;
  return std::max(0.0, yy_ - 2.0 * c.dot(b()) + c.dot(m() * c));
}

void NormalEquations::set(Eigen::MatrixXd m, Eigen::VectorXd b, double yy, std::int64_t n) {
  m_ = std::move(m);
  b_ = std::move(b);
  rows_.resize(0, 0);
  y_.resize(0);
  used_ = 0;
  yy_ = yy;
  n_ = n;
}

}  // namespace resolver
