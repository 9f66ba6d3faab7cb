#include "daemon/core/model/run_estimate.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

namespace resolver {

namespace {

bool usable(const ModelParameter& p) { return std::isfinite(p.value) && std::isfinite(p.std_error) && p.std_error > 0.0; }

}  // namespace

void RunEstimate::add(const Model& window, std::int64_t samples, double revolutions) {
  const std::vector<ModelParameter> params = window.parameters();
  bool restart = windows_ == 0 || window.p_r() != last_.p_r() || window.p() != last_.p() ||
                 window.spec().references() != last_.spec().references() || params.size() != sums_.size();
  for (std::size_t j = 0; !restart && j < params.size(); ++j) restart = params[j].name != sums_[j].name;
  if (restart) {
    sums_.clear();
    for (const ModelParameter& p : params) sums_.push_back(Sums{.name = p.name});
    windows_ = 0;
    samples_ = 0;
    revolutions_ = 0.0;
  }
  last_ = window;
  for (std::size_t j = 0; j < params.size(); ++j) {
    const ModelParameter& p = params[j];
    Sums& s = sums_[j];
    s.plain += p.value;
    if (!usable(p)) continue;
    const double w = 1.0 / (p.std_error * p.std_error);
    s.w += w;
    s.wx += w * p.value;
    s.wxx += w * p.value * p.value;
  }
  ++windows_;
  samples_ += samples;
  revolutions_ += revolutions;
}

Model RunEstimate::combined() const {
  Model out = last_;
  const auto k = static_cast<double>(windows_);
  for (const Sums& s : sums_) {
    if (!(s.w > 0.0)) {  // no window knows its error: the plain mean, error unknown
      out.set(s.name, s.plain / k, std::numeric_limits<double>::quiet_NaN());
      continue;
    }
    const double mean = s.wx / s.w;
    double se = 1.0 / std::sqrt(s.w);
    if (windows_ >= kSpreadWindows) {
      const double chi2 = std::max(0.0, s.wxx - s.wx * mean);
      se = std::sqrt(chi2 / ((k - 1.0) * s.w));
    }
    out.set(s.name, mean, se);
  }
  return out;
}

std::string RunEstimate::basis() const {
  if (windows() >= kSpreadWindows) {
    return fmt::format("the whole run: {} windows ({:.0f} revolutions) combined, inverse-variance weighted; "
                       "robust: window-to-window spread of {} windows",
                       windows(), revolutions_, windows());
  }
  return fmt::format("the whole run: {} window{} ({:.0f} revolutions) combined, inverse-variance weighted; "
                     "formal: from the windows' own errors (the spread needs {} windows)",
                     windows(), windows() == 1 ? "" : "s", revolutions_, kSpreadWindows);
}

}  // namespace resolver
