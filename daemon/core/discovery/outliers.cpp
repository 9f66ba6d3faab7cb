#include "daemon/core/discovery/outliers.h"

#include <algorithm>
#include <cmath>
#include <optional>

namespace resolver {

namespace {
constexpr double kThreshold = 12.0;
constexpr std::size_t kListed = 10;
/// Furthest a line's sample may be (in samples) once flagged ones are taken out (header).
constexpr std::size_t kMaxGap = 4;
/// Passes at most (each peels a burst by a sample at either end; header).
constexpr int kMaxPasses = 8;
/// Later passes look only beside a flag this many times its limit (36 robust sigmas), and
/// flag only samples that far off: a spike that size hides its neighbours. A transient is
/// left as one pass judged it (an instant stop's loop ringing, sampled at four samples a
/// period, had its first sample at 30x and the next ones at a few times the limit: peeled,
/// a chunk and its whole log, whose robust scales differ by 5 %, flagged different rows). A
/// spike this misses is under 36 sigma: ~0.1 of the floor's mean square on 15,000 rows.
constexpr double kPeelAbove = 3.0;

/// A sample's distance from the line through its nearest unflagged neighbours, and the
/// distance above which it is an outlier.
struct Deviation {
  double size = 0.0;   ///< |y_i - line(i)|: a spike's size
  double limit = 0.0;  ///< kThreshold robust sigmas of `size` under white noise
};

class LineTest {
 public:
  /// `half_limit`: kThreshold robust sigmas of half a second difference (the deviation
  /// from the line through both adjacent samples, whose white-noise variance is 1.5 sigma^2).
  LineTest(std::span<const double> y, const std::vector<bool>& usable, const std::vector<bool>& flags,
           double half_limit)
      : y_(y), usable_(usable), flags_(flags), half_limit_(half_limit) {}

  /// |y_i - line| through the second unflagged samples either side (skipping one each
  /// way), or none. It ranks, never tests: beside a pair of spikes the adjacent line
  /// through one of them puts a clean sample as far off as the spikes (a / 2 each),
  /// while this line misses the pair and puts each spike at a.
  [[nodiscard]] std::optional<double> skipping_one(std::size_t i) const {
    const auto p = neighbour(i, -1), q = neighbour(i, +1);
    if (!p || !q) return std::nullopt;
    const auto p2 = neighbour(*p, -1), q2 = neighbour(*q, +1);
    if (!p2 || !q2) return std::nullopt;
    const auto h1 = static_cast<double>(i - *p2), h2 = static_cast<double>(*q2 - i);
    return std::abs(y_[i] - (h2 * y_[*p2] + h1 * y_[*q2]) / (h1 + h2));
  }

  /// Through the unflagged neighbours either side (interpolated) or, at the end of a run,
  /// the two on one side (extrapolated; header). None where neither exists.
  [[nodiscard]] std::optional<Deviation> at(std::size_t i) const {
    const auto p = neighbour(i, -1), q = neighbour(i, +1);
    double line = 0.0, variance = 1.0;  // of y_i - line, in units of one sample's
    if (p && q) {
      const auto h1 = static_cast<double>(i - *p), h2 = static_cast<double>(*q - i);
      const double wp = h2 / (h1 + h2), wq = h1 / (h1 + h2);
      line = wp * y_[*p] + wq * y_[*q];
      variance += wp * wp + wq * wq;
    } else if (p || q) {
      const int step = p ? -1 : +1;
      const std::size_t near = p ? *p : *q;
      const auto far = neighbour(near, step);
      if (!far) return std::nullopt;
      const double r = static_cast<double>(p ? i - near : near - i) / static_cast<double>(p ? near - *far : *far - near);
      line = (1.0 + r) * y_[near] - r * y_[*far];
      variance += (1.0 + r) * (1.0 + r) + r * r;
    } else {
      return std::nullopt;
    }
    return Deviation{std::abs(y_[i] - line), half_limit_ * std::sqrt(variance / 1.5)};
  }

 private:
  /// The nearest sample before (step -1) or after (+1) `i` that is usable and not
  /// flagged, within kMaxGap and with no unusable sample between (that breaks the run).
  [[nodiscard]] std::optional<std::size_t> neighbour(std::size_t i, int step) const {
    const std::size_t n = usable_.size();
    for (std::size_t k = 1; k <= kMaxGap; ++k) {
      if (step < 0 ? i < k : i + k >= n) return std::nullopt;
      const std::size_t j = step < 0 ? i - k : i + k;
      if (!usable_[j]) return std::nullopt;
      if (!flags_[j]) return j;
    }
    return std::nullopt;
  }

  std::span<const double> y_;
  const std::vector<bool>& usable_;
  const std::vector<bool>& flags_;
  double half_limit_;
};

/// The robust sigma of the second differences d over consecutive usable samples: their
/// MAD, bounded below by half the mean |d| (a quantized, slow signal has a zero MAD). With
/// `trimmed` and a nonzero MAD the mean is over the |d| below kThreshold MADs: one-sided
/// 10 A spikes at 50/s put the scale from the plain mean at 10x the noise's (0.44 A for
/// 0.045) and the limit above a pair's half-size. Zero with fewer than 16 differences.
double robust_scale(std::span<const double> y, const std::vector<bool>& usable, bool trimmed) {
  const std::size_t n = y.size();
  std::vector<double> mags;
  mags.reserve(n);
  for (std::size_t i = 1; i + 1 < n; ++i) {
    if (usable[i - 1] && usable[i] && usable[i + 1]) mags.push_back(std::abs(y[i + 1] - 2.0 * y[i] + y[i - 1]));
  }
  if (mags.size() < 16) return 0.0;
  double sum = 0.0;
  for (double m : mags) sum += m;
  auto count = static_cast<double>(mags.size());
  const auto mid = mags.begin() + static_cast<std::ptrdiff_t>(mags.size() / 2);
  std::nth_element(mags.begin(), mid, mags.end());
  const double mad = 1.4826 * *mid;
  if (trimmed && mad > 0.0) {
    sum = 0.0;
    count = 0.0;
    for (double m : mags) {
      if (m > kThreshold * mad) continue;
      sum += m;
      count += 1.0;
    }
  }
  return std::max(mad, 0.5 * 1.2533 * sum / count);
}

}  // namespace

OutlierSignal find_outliers(std::span<const double> t, std::span<const double> y, const std::vector<bool>& usable,
                            std::vector<bool>& flags, const std::string& signal) {
  OutlierSignal out;
  out.signal = signal;
  const std::size_t n = y.size();
  if (flags.size() != n) flags.assign(n, false);
  out.scale = robust_scale(y, usable, false);
  if (!(out.scale > 0.0)) return out;
  std::vector<double> d(n, 0.0);
  std::vector<bool> valid(n, false);
  for (std::size_t i = 1; i + 1 < n; ++i) {
    if (!usable[i - 1] || !usable[i] || !usable[i + 1]) continue;
    d[i] = y[i + 1] - 2.0 * y[i] + y[i - 1];
    valid[i] = true;
  }
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

OutlierSignal find_outlier_bursts(std::span<const double> t, std::span<const std::span<const double>> ys,
                                  const std::vector<bool>& usable, std::vector<bool>& flags, const std::string& signal) {
  OutlierSignal out;
  out.signal = signal;
  const std::size_t n = usable.size();
  if (flags.size() != n) flags.assign(n, false);
  // One test per component, sharing the flags: a spike on one phase current moves i_d and
  // i_q by its projections, and a sample flagged for either is out of both lines.
  struct Component {
    LineTest line;
    std::vector<double> size, limit, rank;
    std::vector<bool> tested;
  };
  std::vector<Component> parts;
  for (std::span<const double> y : ys) {
    const double scale = robust_scale(y, usable, true);
    if (!(scale > 0.0)) continue;
    out.scale = std::max(out.scale, scale);
    parts.push_back(Component{LineTest(y, usable, flags, 0.5 * kThreshold * scale), std::vector<double>(n, 0.0),
                              std::vector<double>(n, 0.0), std::vector<double>(n, 0.0), std::vector<bool>(n, false)});
  }
  std::vector<std::size_t> at, mine;  // the samples (re)tested this pass; those this call flagged
  bool first = true;                  // the first pass ranks peaks by both lines (skipping_one)
  auto test = [&](Component& c, std::size_t i) {
    c.tested[i] = false;
    if (!usable[i] || flags[i]) return;
    const std::optional<Deviation> dev = c.line.at(i);
    if (!dev) return;
    c.size[i] = dev->size;
    c.limit[i] = dev->limit;
    c.rank[i] = dev->size;
    if (first) c.rank[i] = std::max(c.rank[i], c.line.skipping_one(i).value_or(0.0));
    c.tested[i] = true;
  };
  // Flags each tested sample above `above` times its limit whose rank no adjacent tested
  // sample's exceeds (a spike a gives a at itself and about a / 2 beside it). Returns those
  // that far above kPeelAbove times it, whose neighbours the next pass tests again.
  auto flag_peaks = [&](Component& c, double above) {
    std::vector<std::size_t> added, big;
    for (std::size_t i : at) {
      if (!c.tested[i] || c.size[i] <= above * c.limit[i]) continue;
      const double a = c.rank[i];
      if ((i > 0 && c.tested[i - 1] && c.rank[i - 1] > a) || (i + 1 < n && c.tested[i + 1] && c.rank[i + 1] > a)) {
        continue;
      }
      added.push_back(i);
    }
    for (std::size_t i : added) {
      flags[i] = true;
      mine.push_back(i);
      for (Component& other : parts) other.tested[i] = false;
      if (c.size[i] >= kPeelAbove * c.limit[i]) big.push_back(i);
    }
    return big;
  };
  std::vector<std::size_t> big;
  for (std::size_t i = 0; i < n; ++i) at.push_back(i);
  for (Component& c : parts) {
    for (std::size_t i : at) test(c, i);
    const std::vector<std::size_t> b = flag_peaks(c, 1.0);
    big.insert(big.end(), b.begin(), b.end());
  }
  first = false;
  // Later passes (header): a sample's line reaches 2 kMaxGap samples (an end's two
  // neighbours), so those within that of a new flag are tested again.
  for (int pass = 1; pass < kMaxPasses && !big.empty(); ++pass) {
    std::vector<bool> near(n, false);
    for (std::size_t f : big) {
      const std::size_t from = f >= 2 * kMaxGap ? f - 2 * kMaxGap : 0;
      for (std::size_t j = from; j <= std::min(n - 1, f + 2 * kMaxGap); ++j) near[j] = true;
    }
    at.clear();
    for (std::size_t i = 0; i < n; ++i) {
      if (near[i]) at.push_back(i);
    }
    big.clear();
    for (Component& c : parts) {
      for (std::size_t i : at) test(c, i);
      const std::vector<std::size_t> b = flag_peaks(c, kPeelAbove);
      big.insert(big.end(), b.begin(), b.end());
    }
  }
  // A clean sample caught between spikes lies, in every component, on the line through its
  // unflagged neighbours once they are all flagged: it is unflagged.
  std::sort(mine.begin(), mine.end());
  std::vector<std::size_t> kept;
  std::vector<double> spike;
  for (std::size_t i : mine) {
    bool on_line = true;
    double largest = 0.0;
    for (const Component& c : parts) {
      const std::optional<Deviation> dev = c.line.at(i);
      on_line = on_line && dev && dev->size <= dev->limit;
      largest = std::max(largest, dev ? dev->size : c.size[i]);
    }
    if (on_line) continue;
    kept.push_back(i);
    spike.push_back(largest);
  }
  for (std::size_t i : mine) flags[i] = false;
  for (std::size_t k = 0; k < kept.size(); ++k) {
    flags[kept[k]] = true;
    ++out.count;
    out.largest = std::max(out.largest, spike[k]);
    if (out.times.size() < kListed) out.times.push_back(t[kept[k]]);
  }
  return out;
}

}  // namespace resolver
