// Effects own their speed and direction terms (Effect::motion_terms): the
// exported table asks them instead of naming delay.d or backlash.h, and the
// terms it keeps reproduce the model's steady-motion error.
#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "daemon/core/effects/registry.h"
#include "daemon/core/model/calibration_table.h"
#include "daemon/core/model/model.h"

namespace resolver {
namespace {

Model model_of(const std::vector<std::string>& refs, int p_r) {
  return Model(ModelSpec::parse(refs), p_r, 4);
}

TEST(MotionTerms, OnlyDelayAndBacklashHaveThem) {
  // Every other effect's error is a function of the angle and belongs in the table.
  std::vector<std::string> with;
  for (const Effect* e : effect_registry()) {
    if (e->has_motion_terms()) with.emplace_back(e->name());
  }
  EXPECT_EQ(with, (std::vector<std::string>{"backlash", "delay"}));
}

TEST(MotionTerms, TheTableKeepsThemAsScalarsAndLeavesThemOutOfTheCorrection) {
  Model m = model_of({"amplitude_imbalance", "delay", "backlash"}, 3);
  m.set("amplitude_imbalance.alpha", 0.05);
  m.set("delay.d", 2e-5);
  m.set("backlash.h", 1e-3);
  const CalibrationTable t = tabulate(m, 64);
  EXPECT_DOUBLE_EQ(t.delay, 2e-5);
  EXPECT_DOUBLE_EQ(t.backlash, 1e-3);
  // The static table is the model without them: the same as alpha alone.
  Model alone = model_of({"amplitude_imbalance"}, 3);
  alone.set("amplitude_imbalance.alpha", 0.05);
  const CalibrationTable u = tabulate(alone, 64);
  ASSERT_EQ(t.correction.size(), u.correction.size());
  for (std::size_t i = 0; i < t.correction.size(); ++i) EXPECT_DOUBLE_EQ(t.correction[i], u.correction[i]) << i;
  // The model's own fitted values are kept as they were.
  ASSERT_EQ(t.parameters.size(), 3U);
  EXPECT_DOUBLE_EQ(t.parameters[1].value, 2e-5);
}

TEST(MotionTerms, BacklashTermIsHalfThePlayPerResolverPolePair) {
  const Effect* backlash = find_effect("backlash");
  ASSERT_NE(backlash, nullptr);
  const std::vector<double> h{2e-3};
  const MotionTerms m = backlash->motion_terms(h, 3);
  EXPECT_DOUBLE_EQ(m.per_direction_rad, 0.5 * 3 * 2e-3);  // eps = p_r (h/2) sign(omega): backlash.h
  EXPECT_DOUBLE_EQ(m.per_speed_s, 0.0);
}

}  // namespace
}  // namespace resolver
