#include "daemon/core/estimation/revolution_ripple.h"

#include "daemon/core/angles.h"

namespace resolver {

bool RevolutionRipple::update(double theta_e, double cos_e, double sin_e, double i_d, double i_q) {
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
      std::array<std::complex<double>, 3> cd{}, cq{};
      for (std::size_t k = 0; k < kRippleOrders.size(); ++k) {
        cd[k] = scale * (sum_d_[k] - mean_d * sum_w_[k]);
        cq[k] = scale * (sum_q_[k] - mean_q * sum_w_[k]);
      }
      if (ring_d_.size() < static_cast<std::size_t>(window_)) {
        ring_d_.push_back(cd);
        ring_q_.push_back(cq);
      } else {
        ring_d_[ring_next_] = cd;
        ring_q_[ring_next_] = cq;
        ring_next_ = (ring_next_ + 1) % ring_d_.size();
      }
      const double inv = 1.0 / static_cast<double>(ring_d_.size());
      for (std::size_t k = 0; k < kRippleOrders.size(); ++k) {
        std::complex<double> ad{}, aq{};
        for (std::size_t r = 0; r < ring_d_.size(); ++r) {
          ad += ring_d_[r][k];
          aq += ring_q_[r][k];
        }
        last_.d[k] = std::abs(ad) * inv;
        last_.q[k] = std::abs(aq) * inv;
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
    // One sin/cos per sample: exp(-j 2 theta) and exp(-j 6 theta) are powers of exp(-j theta).
    const std::complex<double> w1(cos_e, -sin_e);
    const std::complex<double> w2 = w1 * w1;
    const std::complex<double> w6 = w2 * w2 * w2;
    static_assert(kRippleOrders[0] == 1 && kRippleOrders[1] == 2 && kRippleOrders[2] == 6);
    const std::array<std::complex<double>, 3> ws{w1, w2, w6};
    for (std::size_t k = 0; k < kRippleOrders.size(); ++k) {
      const std::complex<double>& w = ws[k];
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
