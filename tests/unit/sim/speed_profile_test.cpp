#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "daemon/core/angles.h"
#include "tools/sim/speed_profile.h"

namespace resolver {
namespace {

TEST(SimSpeedProfile, IntegratesStepsAndRamps) {
  const SpeedProfile p({{1.0, 200.0, 200.0}, {0.5, 200.0, 1000.0}, {0.5, 1000.0, 1000.0}, {0.25, -300.0, -300.0}});
  EXPECT_DOUBLE_EQ(p.duration(), 2.25);
  // Analytic: area under the rpm curve, converted to rad.
  const double w200 = 200.0 * kTwoPi / 60.0;
  const double w1000 = 1000.0 * kTwoPi / 60.0;
  const double w300 = -300.0 * kTwoPi / 60.0;
  EXPECT_NEAR(p.angle_m(1.0), w200, 1e-12);
  EXPECT_NEAR(p.angle_m(1.25), w200 + 0.25 * w200 + 0.5 * (w1000 - w200) / 0.5 * 0.25 * 0.25, 1e-12);
  EXPECT_NEAR(p.angle_m(2.25), w200 + 0.5 * (w200 + w1000) * 0.5 + 0.5 * w1000 + 0.25 * w300, 1e-12);
  EXPECT_NEAR(p.omega_m(1.25), 0.5 * (w200 + w1000), 1e-12);
  EXPECT_NEAR(p.omega_m(2.0), w300, 1e-12);  // a step: the new segment's speed holds from its start
  // Independent check: the derivative of angle_m is omega_m everywhere (central differences
  // are exact for a quadratic, so only rounding ~1e-16 * angle / h remains).
  const double h = 1e-5;
  for (double t = h; t < p.duration() - h; t += 0.0371) {
    const double numeric = (p.angle_m(t + h) - p.angle_m(t - h)) / (2.0 * h);
    // Across a speed step the difference quotient averages the two speeds: skip those points.
    if (std::abs(t - 2.0) < h) continue;
    ASSERT_NEAR(numeric, p.omega_m(t), 1e-6 * (1.0 + std::abs(p.omega_m(t)))) << t;
  }
}

TEST(SimSpeedProfile, RejectsBadSegments) {
  EXPECT_THROW(SpeedProfile({}), std::invalid_argument);
  try {
    SpeedProfile p({{1.0, 100.0, 100.0}, {0.0, 100.0, 100.0}});
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("segment 2"), std::string::npos) << e.what();
  }
}

TEST(SimSpeedProfile, ParsesTheCliForm) {
  const std::vector<SpeedSegment> s = parse_speed_profile("200:5,200-1000:3,1000:2,-200--100:1.5");
  ASSERT_EQ(s.size(), 4U);
  EXPECT_DOUBLE_EQ(s[0].rpm_start, 200.0);
  EXPECT_DOUBLE_EQ(s[0].rpm_end, 200.0);
  EXPECT_DOUBLE_EQ(s[0].duration_s, 5.0);
  EXPECT_DOUBLE_EQ(s[1].rpm_start, 200.0);
  EXPECT_DOUBLE_EQ(s[1].rpm_end, 1000.0);
  EXPECT_DOUBLE_EQ(s[3].rpm_start, -200.0);
  EXPECT_DOUBLE_EQ(s[3].rpm_end, -100.0);
  EXPECT_DOUBLE_EQ(s[3].duration_s, 1.5);
  for (const char* bad : {"", "200", "200:0", "abc:1", "200-x:1", "200:1,,300:1", "200:-1"}) {
    try {
      (void)parse_speed_profile(bad);
      ADD_FAILURE() << "accepted: " << bad;
    } catch (const InputError& e) {
      EXPECT_EQ(e.fault(), Fault::kUsage);
      EXPECT_EQ(e.where().option, "--profile");
      EXPECT_EQ(std::string(e.what()).rfind("--profile: '" + std::string(bad) + "': segment ", 0), 0U) << e.what();
    }
  }
}

}  // namespace
}  // namespace resolver
