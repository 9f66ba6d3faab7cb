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
  if (sample.has_rd) {
    last_angle_ = unwrap_.update(sample.theta_rd);
    if (!have_angle_) {
      first_angle_ = last_angle_;
      have_angle_ = true;
    }
  }
  return revolutions() >= config_.revolutions || input_.samples.size() >= config_.max_samples;
}

double ModelWindow::revolutions() const {
  return have_angle_ ? std::abs(last_angle_ - first_angle_) / kTwoPi : 0.0;
}

DiscoveryInput ModelWindow::take() {
  DiscoveryInput out = std::move(input_);
  input_ = DiscoveryInput{};
  input_.samples.reserve(out.samples.size());
  unwrap_ = AngleUnwrapper{};
  have_angle_ = false;
  first_angle_ = last_angle_ = 0.0;
  return out;
}

}  // namespace resolver
