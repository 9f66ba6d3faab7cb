#include "daemon/core/estimation/revolution_ripple.h"

#include "daemon/core/angles.h"

namespace resolver {

bool RevolutionRipple::update(double theta_e, double i_d, double i_q) {
  const auto index = static_cast<std::int64_t>(std::floor(theta_e / kTwoPi));
  bool completed = false;
  if (!started_) {
    started_ = true;
    rev_index_ = index;
  } else if (index != rev_index_) {
    // Only a revolution that started on a boundary is complete.
    if (in_revolution_ && n_ > 0) {
      const double n = static_cast<double>(n_);
      const double scale = 2.0 / n;
      const double mean_d = sum_x_d_ / n;
      const double mean_q = sum_x_q_ / n;
      for (std::size_t k = 0; k < kRippleOrders.size(); ++k) {
        last_.d[k] = scale * std::abs(sum_d_[k] - mean_d * sum_w_[k]);
        last_.q[k] = scale * std::abs(sum_q_[k] - mean_q * sum_w_[k]);
      }
      ++revolutions_;
      completed = true;
    }
    in_revolution_ = true;
    rev_index_ = index;
    n_ = 0;
    sum_d_.fill({});
    sum_q_.fill({});
    sum_w_.fill({});
    sum_x_d_ = 0.0;
    sum_x_q_ = 0.0;
  }
  if (in_revolution_) {
    for (std::size_t k = 0; k < kRippleOrders.size(); ++k) {
      const double a = -kRippleOrders[k] * theta_e;
      const std::complex<double> w(std::cos(a), std::sin(a));
      sum_d_[k] += i_d * w;
      sum_q_[k] += i_q * w;
      sum_w_[k] += w;
    }
    sum_x_d_ += i_d;
    sum_x_q_ += i_q;
    ++n_;
  }
  return completed;
}

}  // namespace resolver
