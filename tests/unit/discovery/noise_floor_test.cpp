// The quantum of a channel, as the noise floor needs it (noise_floor.h).
#include "daemon/core/discovery/noise_floor.h"

#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "daemon/core/angles.h"

namespace resolver {
namespace {

constexpr double kLsb = kTwoPi / 65536.0;  // a 16-bit R/D converter [rad]

TEST(ChannelQuantum, QuantizedRampGivesTheLsb) {
  // 0.36 deg per sample is 65.536 LSB: steps of 65 and 66 codes, one LSB apart.
  std::vector<double> v;
  for (int i = 0; i < 2000; ++i) v.push_back(std::floor(i * 65.536) * kLsb);
  EXPECT_NEAR(channel_quantum(v), kLsb, 1e-12);
}

TEST(ChannelQuantum, OneStepSizeIsMotionNotAQuantizer) {
  // A commanded or perfectly smooth reference at a speed commensurate with the sample
  // rate steps by the same amount every sample (and holds still between): that step
  // is the motion. The moteus sweep's commanded angle and a scope's encoder column do this.
  std::vector<double> v(300, 0.0);
  for (int i = 1; i <= 1000; ++i) v.push_back(i * 0.36 * kPi / 180.0);
  for (int i = 0; i < 300; ++i) v.push_back(v.back());
  EXPECT_EQ(channel_quantum(v), 0.0);
}

TEST(ChannelQuantum, ContinuousSignalHasNone) {
  std::vector<double> v;
  for (int i = 0; i < 2000; ++i) v.push_back(std::sin(0.01 * i) + 1e-3 * std::sin(1.7 * i * i));
  EXPECT_LT(channel_quantum(v), 1e-6);
}

}  // namespace
}  // namespace resolver
