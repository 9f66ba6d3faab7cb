// WakePlanner: learns the frame that completes the samples, falls back to
// every frame when the order changes, and never changes a fixed list.
#include <gtest/gtest.h>

#include "daemon/app/wake_planner.h"

namespace resolver {
namespace {

using Ids = std::vector<std::uint32_t>;

/// Feeds `n` completions by `id`; returns the first proposal, if any, and
/// applies it as run_live does after a successful switch.
std::optional<Ids> complete(WakePlanner& p, std::uint32_t id, int n, int* at = nullptr) {
  for (int i = 0; i < n; ++i) {
    if (auto ids = p.on_sample_completed_by(id)) {
      if (at != nullptr) *at = i + 1;
      p.switched(*ids);
      return ids;
    }
  }
  return std::nullopt;
}

TEST(WakePlanner, LearnsTheCompletingFrameAfterAStreak) {
  WakePlanner p(true, {});
  EXPECT_TRUE(p.wake_ids().empty());
  int at = 0;
  // One sample completed by another frame (a start-up glitch) restarts the streak.
  EXPECT_FALSE(complete(p, 0x102, WakePlanner::kLearnSamples - 1));
  EXPECT_FALSE(complete(p, 0x101, 1));
  const auto ids = complete(p, 0x102, WakePlanner::kLearnSamples + 10, &at);
  ASSERT_TRUE(ids);
  EXPECT_EQ(*ids, Ids{0x102});
  EXPECT_EQ(at, WakePlanner::kLearnSamples);
  EXPECT_EQ(p.wake_ids(), Ids{0x102});
  EXPECT_EQ(WakePlanner::describe(p.wake_ids()), "0x102");
}

TEST(WakePlanner, FallsBackWhenSamplesAreCompletedByFramesThatDoNotWake) {
  WakePlanner p(true, {});
  ASSERT_TRUE(complete(p, 0x102, WakePlanner::kLearnSamples));
  // The reference encoder is unplugged: 0x101 completes the samples now.
  EXPECT_FALSE(complete(p, 0x101, WakePlanner::kFallbackSamples - 1));
  EXPECT_FALSE(complete(p, 0x102, 1));  // not in a row
  int at = 0;
  const auto ids = complete(p, 0x101, WakePlanner::kFallbackSamples, &at);
  ASSERT_TRUE(ids);
  EXPECT_TRUE(ids->empty());
  EXPECT_EQ(at, WakePlanner::kFallbackSamples);
  EXPECT_EQ(WakePlanner::describe(p.wake_ids()), "every frame");
  // ... and learns the new one.
  EXPECT_EQ(complete(p, 0x101, WakePlanner::kLearnSamples), Ids{0x101});
}

TEST(WakePlanner, SilenceOfTheWakingFrameFallsBackAtOnce) {
  WakePlanner p(true, {});
  EXPECT_FALSE(p.on_waking_silence());  // every frame wakes already
  ASSERT_TRUE(complete(p, 0x102, WakePlanner::kLearnSamples));
  const auto ids = p.on_waking_silence();
  ASSERT_TRUE(ids);
  EXPECT_TRUE(ids->empty());
  WakePlanner fixed(false, {0x102});
  EXPECT_FALSE(fixed.on_waking_silence());
}

TEST(WakePlanner, AFixedListNeverChanges) {
  WakePlanner fixed(false, {0x101, 0x102});
  EXPECT_FALSE(complete(fixed, 0x100, 10 * WakePlanner::kLearnSamples));
  EXPECT_EQ(fixed.wake_ids(), (Ids{0x101, 0x102}));
  EXPECT_EQ(WakePlanner::describe(fixed.wake_ids()), "0x101, 0x102");
  WakePlanner every(false, {});
  EXPECT_FALSE(complete(every, 0x102, 10 * WakePlanner::kLearnSamples));
  EXPECT_TRUE(every.wake_ids().empty());
}

}  // namespace
}  // namespace resolver
