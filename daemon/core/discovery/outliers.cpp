#include "daemon/core/discovery/outliers.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>

#include <Eigen/Dense>

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
/// A spike a moves the second differences beside it by a and its own by -2a; a kink (the slope
/// of a smooth signal turning at one sample: an instant speed step, a start from standstill)
/// moves only its own. A candidate is a kink, not an outlier, where the second differences
/// beside it are within this share of its own move of the curvature on their side (is_kink;
/// a resolver-sim bench profile's steps from standstill, at 5-15 % offsets, put kinks of 3.5
/// to 13 limits in sin/cos and the position error). A spike gives 1 / 3, a pair or spikes 3
/// apart more; a kink at the limit about 1 / 6 with the noise (sigma sqrt 2 of 12 sigma).
constexpr double kKinkShare = 0.2;

/// Whether the candidate at i is a kink (kKinkShare): d_{i-1} off d_{i-2} and d_{i+1} off
/// d_{i+2} (each side's own curvature: a start from standstill has none before it) by under
/// kKinkShare of d_i off the mean of d_{i-1} and d_{i+1}. False (not judged) where one of
/// y_{i-3} .. y_{i+3} is missing or unusable.
bool is_kink(std::span<const double> y, const std::vector<bool>& usable, std::size_t i) {
  if (i < 3 || i + 3 >= y.size()) return false;
  for (std::size_t j = i - 3; j <= i + 3; ++j) {
    if (!usable[j]) return false;
  }
  auto d = [&](std::size_t j) { return y[j + 1] - 2.0 * y[j] + y[j - 1]; };
  const double own = std::abs(d(i) - 0.5 * (d(i - 1) + d(i + 1)));
  return std::max(std::abs(d(i - 1) - d(i - 2)), std::abs(d(i + 1) - d(i + 2))) < kKinkShare * own;
}

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

  /// Through the two nearest unflagged samples either side by a least-squares parabola, where
  /// the nearest ones are more than a sample away on some side (flagged samples between):
  /// the line across such a gap misses a smooth signal's curvature by h1 h2 / 2 second
  /// differences (a clean sample between spikes one apart, at 15 % offsets and 601 r/min at
  /// 2 kHz, was 1.1 limits off the line and on the parabola). None otherwise.
  [[nodiscard]] std::optional<Deviation> across_gap(std::size_t i) const {
    const auto p = neighbour(i, -1), q = neighbour(i, +1);
    if (!p || !q || *q - *p <= 2) return std::nullopt;
    const auto p2 = neighbour(*p, -1), q2 = neighbour(*q, +1);
    if (!p2 || !q2) return std::nullopt;
    const std::array<std::size_t, 4> at{*p2, *p, *q, *q2};
    // Normal equations of y = a + b x + c x^2 (x = j - i); the prediction at i is a = w . y.
    Eigen::Matrix3d m = Eigen::Matrix3d::Zero();
    std::array<Eigen::Vector3d, 4> rows;
    for (std::size_t k = 0; k < 4; ++k) {
      const double x = static_cast<double>(at[k]) - static_cast<double>(i);
      rows[k] = Eigen::Vector3d(1.0, x, x * x);
      m += rows[k] * rows[k].transpose();
    }
    const Eigen::Vector3d e0 = m.ldlt().solve(Eigen::Vector3d::UnitX());
    double line = 0.0, variance = 1.0;
    for (std::size_t k = 0; k < 4; ++k) {
      const double w = e0.dot(rows[k]);
      line += w * y_[at[k]];
      variance += w * w;
    }
    return Deviation{std::abs(y_[i] - line), half_limit_ * std::sqrt(variance / 1.5)};
  }

  /// Through the unflagged neighbours either side (interpolated) or, at the end of a run,
  /// the two on one side (extrapolated; header). None where neither exists.
  [[nodiscard]] std::optional<Deviation> at(std::size_t i) const {
    double variance = 0.0;
    const std::optional<double> line = line_at(i, variance);
    if (!line) return std::nullopt;
    return Deviation{std::abs(y_[i] - *line), half_limit_ * std::sqrt(variance / 1.5)};
  }

  /// y_i, or where i is flagged the line's value there (at() above): a spike taken out.
  [[nodiscard]] std::optional<double> clean_value(std::size_t i) const {
    double variance = 0.0;
    return flags_[i] ? line_at(i, variance) : std::optional<double>(y_[i]);
  }

 private:
  /// The line of at() at i; `variance` of y_i - line, in units of one sample's.
  [[nodiscard]] std::optional<double> line_at(std::size_t i, double& variance) const {
    const auto p = neighbour(i, -1), q = neighbour(i, +1);
    double line = 0.0;
    variance = 1.0;
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
    return line;
  }

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
    if (is_kink(y, usable, i)) continue;
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
    std::span<const double> y;
    LineTest line;
    std::vector<double> size, limit, rank;
    std::vector<bool> tested;
  };
  std::vector<Component> parts;
  for (std::span<const double> y : ys) {
    const double scale = robust_scale(y, usable, true);
    if (!(scale > 0.0)) continue;
    out.scale = std::max(out.scale, scale);
    parts.push_back(Component{y, LineTest(y, usable, flags, 0.5 * kThreshold * scale), std::vector<double>(n, 0.0),
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
  // Each sample's rank over the components, in units of its limit: the largest. The peak
  // test below compares these, so a spike large in one component outranks its neighbour
  // whose rank another component's spike inflated (sin/cos: a spike on sin moves the angle
  // where sin is small and the radius where it is large; judged one component after the
  // other, a clean sample two from an angle spike, just over its angle limit beside a
  // radius spike, was flagged first, and the line of the clean one beside it then ran
  // through the radius spike: two clean samples flagged).
  std::vector<double> score(n, 0.0);
  std::vector<bool> scored(n, false);
  auto rank_all = [&]() {
    for (std::size_t i : at) {
      scored[i] = false;
      score[i] = 0.0;
      for (const Component& c : parts) {
        if (!c.tested[i] || !(c.limit[i] > 0.0)) continue;
        scored[i] = true;
        score[i] = std::max(score[i], c.rank[i] / c.limit[i]);
      }
    }
  };
  // A kink (kKinkShare) in every component where the sample is over its limit (in the others
  // a kink below the limit is not told from the curvature's own changes).
  auto kink = [&](std::size_t i) {
    return std::all_of(parts.begin(), parts.end(), [&](const Component& c) {
      return !(c.tested[i] && c.size[i] > c.limit[i]) || is_kink(c.y, usable, i);
    });
  };
  // Over `above` times its limit in some component.
  auto over = [&](std::size_t i, double above) {
    return scored[i] && std::any_of(parts.begin(), parts.end(), [&](const Component& c) {
             return c.tested[i] && c.size[i] > above * c.limit[i];
           });
  };
  // Flags each sample over `above` times its limit whose score no adjacent sample's over it
  // exceeds (a spike a gives a at itself and about a / 2 beside it) and, in the first pass,
  // is no kink. Returns those kPeelAbove times it, whose neighbours the next pass tests again.
  auto flag_peaks = [&](double above) {
    std::vector<std::size_t> added, big;
    for (std::size_t i : at) {
      if (!over(i, above)) continue;
      // Only neighbours over the limit compete: the middle of a burst of three is on the
      // line through its two spike neighbours, and its rank (the line skipping one) alone
      // would outrank both ends, so none was flagged (three spikes in a row, all missed).
      const double a = score[i];
      if ((i > 0 && over(i - 1, above) && score[i - 1] > a) || (i + 1 < n && over(i + 1, above) && score[i + 1] > a)) {
        continue;
      }
      if (first && kink(i)) continue;
      added.push_back(i);
    }
    for (std::size_t i : added) {
      flags[i] = true;
      mine.push_back(i);
      bool large = false;
      for (const Component& c : parts) large = large || (c.tested[i] && c.size[i] >= kPeelAbove * c.limit[i]);
      if (large) big.push_back(i);
    }
    return big;
  };
  std::vector<std::size_t> big;
  for (std::size_t i = 0; i < n; ++i) at.push_back(i);
  for (Component& c : parts) {
    for (std::size_t i : at) test(c, i);
  }
  rank_all();
  big = flag_peaks(1.0);
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
    for (Component& c : parts) {
      for (std::size_t i : at) test(c, i);
    }
    rank_all();
    big = flag_peaks(kPeelAbove);
  }
  // A kink (kKinkShare) the first pass could not tell, a spike near it in is_kink's samples,
  // is told with the spikes out (each flagged one at its line's value): unflagged for good
  // where it is one in every component over its limit.
  auto kink_at_end = [&](std::size_t i) {
    if (i < 3 || i + 3 >= n || flags[i - 1] || flags[i + 1]) return false;
    flags[i] = false;
    bool over_limit = false, kinked = true;
    std::array<double, 7> local{};
    const std::vector<bool> all_usable(local.size(), true);
    for (const Component& c : parts) {
      const std::optional<Deviation> d0 = c.line.at(i);
      if (!d0 || d0->size <= d0->limit) continue;
      over_limit = true;
      for (std::size_t k = 0; k < local.size() && kinked; ++k) {
        const std::size_t j = i - 3 + k;
        const std::optional<double> v = usable[j] ? c.line.clean_value(j) : std::nullopt;
        kinked = v.has_value();
        local[k] = v.value_or(0.0);
      }
      kinked = kinked && is_kink(local, all_usable, 3);
    }
    const bool told = over_limit && kinked;
    flags[i] = !told;
    return told;
  };
  // A clean sample caught between spikes lies, in every component, on the line through its
  // unflagged neighbours once they are all flagged (or on the parabola across them:
  // LineTest::across_gap): it is unflagged, and so is a kink told at the end.
  std::sort(mine.begin(), mine.end());
  std::vector<std::size_t> kept;
  std::vector<double> spike;
  for (std::size_t i : mine) {
    bool on_line = true;
    double largest = 0.0;
    for (const Component& c : parts) {
      const std::optional<Deviation> dev = c.line.at(i), curved = c.line.across_gap(i);
      on_line = on_line && dev && (dev->size <= dev->limit || (curved && curved->size <= curved->limit));
      largest = std::max(largest, dev ? dev->size : c.size[i]);
    }
    if (on_line || kink_at_end(i)) continue;
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
