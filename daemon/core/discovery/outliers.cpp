#include "daemon/core/discovery/outliers.h"

#include <algorithm>
#include <cmath>

namespace resolver {

namespace {
constexpr double kThreshold = 12.0;
constexpr std::size_t kListed = 10;
}  // namespace

OutlierSignal find_outliers(std::span<const double> t, std::span<const double> y, const std::vector<bool>& usable,
                            std::vector<bool>& flags, const std::string& signal) {
  OutlierSignal out;
  out.signal = signal;
  const std::size_t n = y.size();
  if (flags.size() != n) flags.assign(n, false);
  std::vector<double> d(n, 0.0);
  std::vector<bool> valid(n, false);
  std::vector<double> mags;
  mags.reserve(n);
  double sum = 0.0;
  for (std::size_t i = 1; i + 1 < n; ++i) {
    if (!usable[i - 1] || !usable[i] || !usable[i + 1]) continue;
    d[i] = y[i + 1] - 2.0 * y[i] + y[i - 1];
    valid[i] = true;
    mags.push_back(std::abs(d[i]));
    sum += std::abs(d[i]);
  }
  if (mags.size() < 16) return out;
  const auto mid = mags.begin() + static_cast<std::ptrdiff_t>(mags.size() / 2);
  std::nth_element(mags.begin(), mid, mags.end());
  const double mad = 1.4826 * *mid;
  const double mean_based = 1.2533 * sum / static_cast<double>(mags.size());
  out.scale = std::max(mad, 0.5 * mean_based);
  if (!(out.scale > 0.0)) return out;
  for (std::size_t i = 1; i + 1 < n; ++i) {
    if (!valid[i]) continue;
    const double a = std::abs(d[i]);
    if (a <= kThreshold * out.scale) continue;
    if ((valid[i - 1] && std::abs(d[i - 1]) > a) || (valid[i + 1] && std::abs(d[i + 1]) > a)) continue;
    if (!flags[i]) {
      flags[i] = true;
      ++out.count;
      out.largest = std::max(out.largest, a / 2.0);  // the pattern (a, -2a, a): the spike is |d_i| / 2
      if (out.times.size() < kListed) out.times.push_back(t[i]);
    }
  }
  return out;
}

}  // namespace resolver
