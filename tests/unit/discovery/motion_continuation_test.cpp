// A later chunk of a log goes on from where the earlier one left the rotor
// (PrepareOptions::continuation): the direction held through a standstill, and the
// travel since the last reversal (backlash's take-up), as the whole log has them.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "daemon/core/discovery/motion.h"
#include "daemon/core/discovery/prepare.h"
#include "tests/unit/discovery/simulated_input.h"

namespace resolver {
namespace {

// A chunk that starts at rest: the direction before its first motion is the one held
// before it, not its first motion's.
TEST(MotionContinuation, TheDirectionHeldBeforeAChunkStartsItsStandstill) {
  std::vector<double> t, angle;
  for (int i = 0; i < 400; ++i) {
    t.push_back(1e-3 * i);
    angle.push_back(i < 200 ? 1.0 : 1.0 + 2.0 * (t.back() - 0.2));  // at rest, then forward at 2 rad/s
  }
  MotionSummary fresh, held;
  const std::vector<MotionSample> a = analyse_motion(t, angle, fresh);
  const std::vector<MotionSample> b = analyse_motion(t, angle, held, -1.0);
  EXPECT_EQ(a.front().direction, 1.0);   // the first motion's
  EXPECT_EQ(b.front().direction, -1.0);  // held from before the chunk
  EXPECT_EQ(b.back().direction, 1.0);
  EXPECT_EQ(fresh.reversals, 0);
  EXPECT_EQ(held.reversals, 1);  // the turn at the chunk's start, as the whole log counts it
}

// An out-and-back cut during the take-up after the reversal: the second chunk's rows
// carry the whole log's travel since the reversal and direction, row for row.
TEST(MotionContinuation, ASecondChunkHasTheWholeLogsTakeUp) {
  const DiscoveryInput whole = simulate({"amplitude_imbalance:alpha=0.003", "backlash:h=0.004"},
                                        {{1.0, 100.0, 100.0}, {0.4, 100.0, -100.0}, {1.0, -100.0, -100.0}});
  const double cut = 1.2;  // the speed crosses zero at 1.2 s: the take-up is under way
  DiscoveryInput first = whole, second = whole;
  std::erase_if(first.samples, [&](const Sample& s) { return s.t >= cut; });
  std::erase_if(second.samples, [&](const Sample& s) { return s.t < cut; });
  const PreparedLog all = prepare_log(whole);
  const PreparedLog one = prepare_log(first);
  ASSERT_TRUE(one.continuation.valid);
  PrepareOptions go_on;
  go_on.continuation = one.continuation;
  const PreparedLog two = prepare_log(second, go_on);
  const PreparedLog afresh = prepare_log(second);
  const std::size_t offset = first.samples.size();
  int mismatched_afresh = 0;
  for (std::size_t i = 0; i < two.rows.size(); ++i) {
    const SignatureRow& w = all.rows[offset + i].sig;
    const SignatureRow& g = two.rows[i].sig;
    // The same sample: the same direction; the travel to 1e-9 rad (the angle between the
    // chunks is found from the reference's wrap, exact to rounding).
    ASSERT_EQ(g.direction, w.direction) << "row " << i;
    if (std::isinf(w.since_reversal)) {
      EXPECT_TRUE(std::isinf(g.since_reversal)) << "row " << i;
    } else {
      EXPECT_NEAR(g.since_reversal, w.since_reversal, 1e-9) << "row " << i;
    }
    const SignatureRow& f = afresh.rows[i].sig;
    if (f.direction != w.direction || std::isinf(f.since_reversal) != std::isinf(w.since_reversal)) ++mismatched_afresh;
  }
  // The control: started afresh the chunk has no reversal and its own first direction.
  EXPECT_GT(mismatched_afresh, 0);
}

}  // namespace
}  // namespace resolver
