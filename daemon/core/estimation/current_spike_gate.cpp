#include "daemon/core/estimation/current_spike_gate.h"

#include <algorithm>
#include <cmath>

namespace resolver {

void CurrentSpikeGate::restart(const Point& p) {
  last_ = p;
  points_ = 1;
  run_ = 0;
}

double CurrentSpikeGate::sigma(const std::array<double, kWindow>& window) const {
  std::array<double, kWindow> v = window;
  const auto end = v.begin() + static_cast<std::ptrdiff_t>(filled_);
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(filled_ / 2);
  std::nth_element(v.begin(), mid, end);
  return 1.4826 * *mid;
}

bool CurrentSpikeGate::pass(double t, double i_d, double i_q) {
  const Point p{t, i_d, i_q};
  if (!std::isfinite(t) || !std::isfinite(i_d) || !std::isfinite(i_q)) return true;  // nothing to judge
  if (points_ < 2) {
    if (points_ == 1 && !(t > last_.t)) {
      restart(p);
      return true;
    }
    before_ = last_;
    last_ = p;
    ++points_;
    return true;
  }
  const double period = last_.t - before_.t;
  const double r = (t - last_.t) / period;
  if (!(period > 0.0) || !(r > 0.0) || r > kMaxGap) {
    restart(p);
    return true;
  }
  // The line through the last two good samples, extrapolated to t.
  estimate_ = {last_.d + r * (last_.d - before_.d), last_.q + r * (last_.q - before_.q)};
  const double e_d = i_d - estimate_.d;
  const double e_q = i_q - estimate_.q;
  res_d_[next_] = std::abs(e_d);
  res_q_[next_] = std::abs(e_q);
  next_ = (next_ + 1) % kWindow;
  filled_ = std::min(filled_ + 1, kWindow);
  if (filled_ == kWindow) {
    if (++since_scale_ >= kScaleEvery || !(sigma_d_ > 0.0 || sigma_q_ > 0.0)) {
      since_scale_ = 0;
      sigma_d_ = sigma(res_d_);
      sigma_q_ = sigma(res_q_);
    }
    // The robust sigmas are of one-step residuals; r steps out the residual's noise is
    // sqrt((1 + (1 + r)^2 + r^2) / 6) of theirs (a burst's later samples: r up to kMaxRun).
    const double wider = r > 1.5 ? std::sqrt((1.0 + (1.0 + r) * (1.0 + r) + r * r) / 6.0) : 1.0;
    const double sd = sigma_d_ * wider, sq = sigma_q_ * wider;
    const bool spike = (sd > 0.0 && std::abs(e_d) > kThreshold * sd) || (sq > 0.0 && std::abs(e_q) > kThreshold * sq);
    if (spike && ++run_ <= kMaxRun) {
      ++rejected_;
      return false;
    }
    if (spike) {  // a level that moved, not a spike (header)
      restart(p);
      return true;
    }
  }
  run_ = 0;
  before_ = last_;
  last_ = p;
  return true;
}

}  // namespace resolver
