// The impulsive-sample test (outliers.h) on spikes alone, in pairs, bursts and at a run's
// ends, on white noise: every spike found, no clean sample kept.
#include "daemon/core/discovery/outliers.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <span>
#include <random>
#include <set>
#include <vector>

namespace resolver {
namespace {

constexpr double kSigma = 0.02;  // [A] a phase current's white noise (resolver-sim's default)
constexpr double kSpike = 10.0;  // [A] 500 sigma: no doubt which samples are spikes

/// Flagged indices of a noisy, slowly turning signal with spikes at `at`.
std::set<std::size_t> flagged(const std::set<std::size_t>& at, std::size_t n = 2000) {
  std::mt19937_64 engine(7);
  std::normal_distribution<double> noise(0.0, kSigma);
  std::vector<double> t(n), y(n);
  for (std::size_t i = 0; i < n; ++i) {
    t[i] = 5e-4 * static_cast<double>(i);
    y[i] = 10.0 + 0.5 * std::sin(2.0 * M_PI * 20.0 * t[i]) + noise(engine) + (at.count(i) ? kSpike : 0.0);
  }
  std::vector<bool> usable(n, true), flags;
  const std::array<std::span<const double>, 1> ys{y};
  const OutlierSignal o = find_outlier_bursts(t, ys, usable, flags, "i_dq");
  std::set<std::size_t> out;
  for (std::size_t i = 0; i < n; ++i) {
    if (flags[i]) out.insert(i);
  }
  EXPECT_EQ(o.count, static_cast<std::int64_t>(out.size()));
  return out;
}

TEST(Outliers, WhiteNoiseHasNone) { EXPECT_TRUE(flagged({}).empty()); }

TEST(Outliers, ASpikeAloneIsFound) { EXPECT_EQ(flagged({500}), (std::set<std::size_t>{500})); }

TEST(Outliers, SpikesSideBySideAreBothFound) {
  EXPECT_EQ(flagged({500, 501}), (std::set<std::size_t>{500, 501}));
}

TEST(Outliers, SpikesOneApartAreFoundAndTheSampleBetweenIsNot) {
  EXPECT_EQ(flagged({500, 502}), (std::set<std::size_t>{500, 502}));
  EXPECT_EQ(flagged({500, 501, 503}), (std::set<std::size_t>{500, 501, 503}));
}

TEST(Outliers, ABurstOfFourIsFound) {
  EXPECT_EQ(flagged({700, 701, 702, 703}), (std::set<std::size_t>{700, 701, 702, 703}));
}

TEST(Outliers, OnePassMissesOneOfAPairAsBefore) {
  // The control: the resolver's signals keep the single pass (outliers.h), which a pair
  // of spikes side by side defeats: one is left in.
  std::vector<double> t(2000), y(2000, 0.0);
  for (std::size_t i = 0; i < t.size(); ++i) {
    t[i] = 5e-4 * static_cast<double>(i);
    y[i] = kSigma * std::sin(1.7 * static_cast<double>(i * i));  // deterministic, noise-like
  }
  y[500] += kSpike;
  y[501] += kSpike;
  std::vector<bool> usable(t.size(), true), flags;
  EXPECT_EQ(find_outliers(t, y, usable, flags, "sin_cos").count, 1);
}

TEST(Outliers, SpikesAtARunsEndsAreFound) {
  EXPECT_EQ(flagged({0, 1999}), (std::set<std::size_t>{0, 1999}));
  EXPECT_EQ(flagged({1998, 1999}), (std::set<std::size_t>{1998, 1999}));
}

}  // namespace
}  // namespace resolver
