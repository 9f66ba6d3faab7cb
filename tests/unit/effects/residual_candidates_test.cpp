// Effects own their harmonic candidates (Effect::residual_candidates): given the
// residual's orders, the winding and mechanical harmonics name the parameters
// discovery tries (Hanselman eq. 8-9: a residual at m theta is K_{m+1} or
// K_{m-1} opposite), with their phase and as a family only offline.
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "daemon/core/effects/registry.h"

namespace resolver {
namespace {

/// A residual with fixed significant orders per angle.
class FixedSpectrum final : public ResidualSpectrum {
 public:
  FixedSpectrum(std::vector<int> theta, std::vector<int> mech) : theta_(std::move(theta)), mech_(std::move(mech)) {}
  [[nodiscard]] std::vector<int> significant(Angle angle, int lowest, int most) const override {
    std::vector<int> out;
    for (int m : angle == Angle::kResolver ? theta_ : mech_) {
      if (m >= lowest && static_cast<int>(out.size()) < most) out.push_back(m);
    }
    return out;
  }
  [[nodiscard]] std::vector<int> strongest(Angle angle, int lowest) const override {
    return significant(angle, lowest, 2);
  }

 private:
  std::vector<int> theta_, mech_;
};

std::vector<std::vector<std::string>> listed(const std::vector<CandidateParams>& sets) {
  std::vector<std::vector<std::string>> out;
  for (const CandidateParams& c : sets) {
    if (!c.family) out.push_back(c.groups.front());
  }
  return out;
}

TEST(ResidualCandidates, WindingHarmonicsFollowTheResidualOrders) {
  const Effect* h = find_effect("harmonics");
  ASSERT_NE(h, nullptr);
  const FixedSpectrum residual({4, 1, 7}, {});
  const auto live = h->residual_candidates(residual, false);
  ASSERT_TRUE(live.has_value());
  // Orders 4 and 1 (the two strongest): k5 or k3_opp, then k2 or k0; no phase, no family live.
  EXPECT_EQ(listed(*live), (std::vector<std::vector<std::string>>{{"k5"}, {"k3_opp"}, {"k2"}, {"k0"}}));
  const auto offline = h->residual_candidates(residual, true);
  ASSERT_TRUE(offline.has_value());
  EXPECT_EQ(listed(*offline), (std::vector<std::vector<std::string>>{
                                  {"k5"}, {"k5", "k5_q"}, {"k3_opp"}, {"k3_opp", "k3_opp_q"}, {"k2"}, {"k2", "k2_q"}, {"k0"}}));
  ASSERT_TRUE(offline->back().family);
  EXPECT_EQ(offline->back().groups, (std::vector<std::vector<std::string>>{{"k5", "k5_q"}, {"k8", "k8_q"}}));
  // Every name is one of the effect's parameters.
  for (const CandidateParams& c : *offline) {
    for (const auto& g : c.groups) {
      for (const std::string& name : g) EXPECT_GE(find_param(*h, name), 0) << name;
    }
  }
}

TEST(ResidualCandidates, MechanicalHarmonicsLeaveOrderOneToEccentricity) {
  const Effect* m = find_effect("mechanical_harmonics");
  ASSERT_NE(m, nullptr);
  const FixedSpectrum residual({}, {1, 6, 2});
  const auto sets = m->residual_candidates(residual, false);
  ASSERT_TRUE(sets.has_value());
  EXPECT_EQ(listed(*sets), (std::vector<std::vector<std::string>>{{"a6", "b6"}, {"a2", "b2"}}));
}

TEST(ResidualCandidates, OtherEffectsUseTheirDefaults) {
  const FixedSpectrum residual({2}, {2});
  for (const Effect* e : effect_registry()) {
    if (e->name() == "harmonics" || e->name() == "mechanical_harmonics") continue;
    EXPECT_FALSE(e->residual_candidates(residual, true).has_value()) << e->name();
  }
}

}  // namespace
}  // namespace resolver
