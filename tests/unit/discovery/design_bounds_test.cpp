// Design::pushed_past_bound on an inverse-square parameter (the tracking loop's
// z = 1/omega_n^2): a fitted loop is inside its range both ways; only the ideal
// converter (z = 0) holds against a step past it.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "daemon/core/effects/tracking_loop.h"
#include "daemon/core/model/design.h"
#include "daemon/core/model/model_spec.h"

namespace resolver {
namespace {

Design loop_at(double omega_n) {
  const ModelSpec spec = ModelSpec::parse(std::vector<std::string>{"tracking_loop"});
  std::vector<double> values{omega_n, 0.7};
  return Design(spec, {values}, {});
}

TEST(DesignBounds, AFittedLoopMovesBothWays) {
  const Design d = loop_at(3000.0);
  const int col = d.term_column(0);
  // dz > 0 is a slower loop: it was held as "past the top" (z(1e6 rad/s) = 1e-12 taken for the top).
  EXPECT_FALSE(d.pushed_past_bound(col, +1e-9));
  EXPECT_FALSE(d.pushed_past_bound(col, -1e-9));
}

TEST(DesignBounds, TheIdealConverterHoldsAgainstAFasterThanIdealStep) {
  const Design d = loop_at(0.0);  // ideal: z = 0
  const int col = d.term_column(0);
  EXPECT_TRUE(d.pushed_past_bound(col, -1e-9));
  EXPECT_FALSE(d.pushed_past_bound(col, +1e-9));
}

TEST(DesignBounds, ADampingRatioMovesByAtMostAFactorTwoPerStep) {
  // Linearised at 0.7 a lightly damped loop's (0.05) first step asked for zeta 0.01, the
  // bound, where the balance has no steady state (design.cpp kScaleStep).
  const ModelSpec spec = ModelSpec::parse(std::vector<std::string>{"tracking_loop(omega_n,zeta)"});
  Design d(spec, {{2000.0, 0.7}}, {});
  Eigen::VectorXd dz = Eigen::VectorXd::Zero(d.columns());
  dz[d.term_column(0) + 1] = -0.69;
  d.step(dz);
  EXPECT_DOUBLE_EQ(d.terms()[0].values[1], 0.35);
  dz[d.term_column(0) + 1] = +5.0;
  d.step(dz);
  EXPECT_DOUBLE_EQ(d.terms()[0].values[1], 0.7);
  // The control: a step within the factor is taken as it is.
  dz[d.term_column(0) + 1] = -0.2;
  d.step(dz);
  EXPECT_DOUBLE_EQ(d.terms()[0].values[1], 0.5);
}

}  // namespace
}  // namespace resolver
