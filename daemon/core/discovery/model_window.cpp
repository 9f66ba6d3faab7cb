#include "daemon/core/discovery/model_window.h"

#include <cmath>
#include <utility>

namespace resolver {

bool ModelWindow::add(const Sample& sample, int p_r, int p) {
  if (!input_.samples.empty() && (p_r != input_.p_r || p != input_.p)) {
    (void)take();  // the fit assumes one set of pole pairs: start again
  }
  input_.p_r = p_r;
  input_.p = p;
  input_.samples.push_back(sample);
  // Revolutions travelled, either way: a whole turn from the last counted one
  // (out-and-back sweeps count both ways; jitter at a standstill counts nothing).
  const bool angle = sample.has_rd || sample.has_sincos;
  if (angle) {
    const double a = unwrap_.update(sample.has_rd ? sample.theta_rd : std::atan2(sample.sin, sample.cos));
    if (!have_angle_) {
      anchor_ = a;
      first_angle_ = a;
      first_t_ = sample.t;
      have_angle_ = true;
    }
    last_angle_ = a;
    last_t_ = sample.t;
    while (std::abs(a - anchor_) >= kTwoPi) {
      anchor_ += a > anchor_ ? kTwoPi : -kTwoPi;
      ++turns_;
    }
    partial_ = std::abs(a - anchor_) / kTwoPi;
  }
  return revolutions() >= config_.revolutions || input_.samples.size() >= config_.max_samples;
}

double ModelWindow::revolutions() const { return static_cast<double>(turns_) + partial_; }

double ModelWindow::mean_speed() const {
  const double dt = last_t_ - first_t_;
  return have_angle_ && dt > 0.0 ? (last_angle_ - first_angle_) / dt : 0.0;
}

DiscoveryInput ModelWindow::take() {
  DiscoveryInput out = std::move(input_);
  input_ = DiscoveryInput{};
  input_.samples.reserve(out.samples.size());
  unwrap_ = AngleUnwrapper{};
  have_angle_ = false;
  anchor_ = 0.0;
  turns_ = 0;
  partial_ = 0.0;
  first_angle_ = first_t_ = last_angle_ = last_t_ = 0.0;
  return out;
}

}  // namespace resolver
