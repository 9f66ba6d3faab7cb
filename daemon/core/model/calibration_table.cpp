#include "daemon/core/model/calibration_table.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "daemon/core/angles.h"
#include "daemon/core/effects/registry.h"
#include "daemon/core/model/compensator.h"

namespace resolver {

namespace {

/// The static correction at measured mechanical angle x: the model inverted at zero
/// speed, with the resolver's cycle given by x itself.
double static_correction(const Model& m, double x) {
  SignatureRow row;
  row.p_r = m.p_r();
  row.p = m.p();
  const double theta_meas = m.p_r() * x;
  double eps = 0.0;
  for (int i = 0; i < 6; ++i) {  // fixed point (compensator.h): (d eps / d theta)^6 of the error left
    row.theta = theta_meas + eps;
    row.theta_m = row.theta / m.p_r();
    eps = m.predict(row).rd;
  }
  return eps;
}

/// The model without the effects whose error is a speed or direction term
/// (their parameters at neutral), and those terms summed.
Model statics_of(const Model& model, MotionTerms& terms) {
  Model statics = model;
  const ModelSpec& spec = model.spec();
  for (std::size_t i = 0; i < spec.terms.size(); ++i) {
    const ModelTerm& term = spec.terms[i];
    if (!term.effect->has_motion_terms()) continue;
    const MotionTerms m = term.effect->motion_terms(model.values()[i], model.p_r());
    terms.per_speed_s += m.per_speed_s;
    terms.per_direction_rad += m.per_direction_rad;
    for (std::size_t j = 0; j < term.params.size(); ++j) {
      const ParamInfo& info = term.effect->params()[static_cast<std::size_t>(term.params[j])];
      statics.set(term.param_name(j), info.neutral);
    }
  }
  return statics;
}

}  // namespace

double CalibrationTable::at(double x) const {
  const auto n = static_cast<double>(correction.size());
  const double u = wrap_2pi(x) / kTwoPi * n;
  const auto i = static_cast<std::size_t>(std::floor(u)) % correction.size();
  const std::size_t j = (i + 1) % correction.size();
  const double f = u - std::floor(u);
  return correction[i] + f * (correction[j] - correction[i]);
}

CalibrationTable tabulate(const Model& model, int points, int fourier_orders) {
  if (points < 8) throw std::invalid_argument("export: --points must be at least 8");
  CalibrationTable t;
  t.p_r = model.p_r();
  t.p = model.p();
  t.model = model.spec().references();
  t.parameters = model.parameters();
  // Speed and direction terms stay scalars; the table is the model without them.
  MotionTerms terms;
  const Model statics = statics_of(model, terms);
  t.delay = terms.per_speed_s;
  t.backlash = 2.0 * terms.per_direction_rad / model.p_r();  // the file's h: p_r (h/2) sign(omega)
  const auto n = static_cast<std::size_t>(points);
  t.correction.resize(n);
  for (std::size_t i = 0; i < n; ++i) t.correction[i] = static_correction(statics, kTwoPi * static_cast<double>(i) / points);
  // Interpolation error on a 16x finer grid.
  const int fine = 16 * points;
  for (int i = 0; i < fine; ++i) {
    const double x = kTwoPi * i / fine;
    t.interpolation_error = std::max(t.interpolation_error, std::abs(static_correction(statics, x) - t.at(x)));
  }
  // Fourier coefficients of the sampled table (DFT; exact for orders below N/2).
  const int orders = std::min(fourier_orders, points / 2 - 1);
  for (int k = 0; k <= orders; ++k) {
    double ak = 0.0, bk = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      const double x = kTwoPi * static_cast<double>(i) / points;
      ak += t.correction[i] * std::cos(k * x);
      bk += t.correction[i] * std::sin(k * x);
    }
    const double scale = (k == 0 ? 1.0 : 2.0) / points;
    t.a.push_back(ak * scale);
    t.b.push_back(bk * scale);
  }
  return t;
}

double TableCompensator::correct(double theta_meas, double omega, double theta_m_ref) {
  if (omega > 0.0) direction_ = 1.0;
  if (omega < 0.0) direction_ = -1.0;
  const double cont = unwrap_.update(wrap_2pi(theta_meas));
  if (!std::isnan(theta_m_ref)) {
    const double offset = wrap_pi(theta_m_ref - cont / table_.p_r);
    if (!cycle_known_) {
      cycle_offset_ = offset;
      cycle_known_ = true;
    } else {
      const double d = wrap_pi(offset - cycle_offset_);
      cycle_offset_ += std::abs(d) > 0.1 ? d : 0.01 * d;
    }
  }
  const double x = cont / table_.p_r + cycle_offset_;
  const double eps = table_.at(x) + omega * table_.delay + 0.5 * table_.p_r * table_.backlash * direction_;
  return wrap_2pi(theta_meas + eps);
}

}  // namespace resolver
