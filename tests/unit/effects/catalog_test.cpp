#include <gtest/gtest.h>

#include <set>
#include <string>

#include "daemon/core/effects/effect_catalog.h"

namespace resolver {
namespace {

TEST(EffectsCatalog, HasTheFixedNamesInDesignOrder) {
  const std::vector<std::string> expected{"amplitude_imbalance", "quadrature",      "offsets",
                                          "harmonics",           "sampling_skew",   "tracking_loop",
                                          "quantization",        "eccentricity",    "mounting_offset",
                                          "current_offsets",     "current_gain_mismatch", "dead_time",
                                          "noise"};
  ASSERT_EQ(effect_catalog().size(), expected.size());
  for (std::size_t i = 0; i < expected.size(); ++i) EXPECT_EQ(effect_catalog()[i].name, expected[i]);
  for (const EffectInfo& e : effect_catalog()) {
    EXPECT_FALSE(e.parameters.empty()) << e.name;
    EXPECT_EQ(e.implemented, e.active != nullptr) << e.name;
    std::set<std::string_view> names;
    for (const EffectParameter& p : e.parameters) {
      EXPECT_TRUE(names.insert(p.name).second) << e.name << " repeats " << p.name;
      EXPECT_EQ(p.unit.front(), '[') << p.name;
      EXPECT_EQ(e.implemented, p.set != nullptr && p.get != nullptr) << p.name;
      EXPECT_LT(p.min, p.max) << p.name;
    }
  }
}

TEST(EffectsCatalog, SpecsSetTheParameters) {
  SensorChainConfig c;
  EXPECT_FALSE(apply_effect_spec(c, "amplitude_imbalance:alpha=0.003"));
  EXPECT_FALSE(apply_effect_spec(c, "quadrature:beta=0.004"));
  EXPECT_FALSE(apply_effect_spec(c, "offsets:o_s=0.001,o_c=-0.002"));
  EXPECT_FALSE(apply_effect_spec(c, " tracking_loop : omega_n = 3000 , zeta=0.7 "));
  EXPECT_FALSE(apply_effect_spec(c, "noise:sigma_sc=2"));
  EXPECT_FALSE(apply_effect_spec(c, "quantization:rd_bits=12"));
  EXPECT_FALSE(apply_effect_spec(c, "harmonics:k0=0.001,k3=-2e-4,k16=1e-5"));
  EXPECT_DOUBLE_EQ(c.amplitude_imbalance.alpha, 0.003);
  EXPECT_DOUBLE_EQ(c.quadrature.beta, 0.004);
  EXPECT_DOUBLE_EQ(c.offsets.o_s, 0.001);
  EXPECT_DOUBLE_EQ(c.offsets.o_c, -0.002);
  EXPECT_DOUBLE_EQ(c.tracking_loop.omega_n, 3000.0);
  EXPECT_DOUBLE_EQ(c.tracking_loop.zeta, 0.7);
  EXPECT_DOUBLE_EQ(c.noise.sigma_sc, 2.0);
  EXPECT_EQ(c.quantization.rd_bits, 12);
  EXPECT_DOUBLE_EQ(c.harmonics.k0, 0.001);
  EXPECT_DOUBLE_EQ(c.harmonics.k[3], -2e-4);
  EXPECT_DOUBLE_EQ(c.harmonics.k[16], 1e-5);

  const std::vector<EffectValues> active = active_effect_values(c);
  std::vector<std::string_view> names;
  for (const EffectValues& v : active) names.push_back(v.effect);
  EXPECT_EQ(names, (std::vector<std::string_view>{"amplitude_imbalance", "quadrature", "offsets", "harmonics",
                                                  "tracking_loop", "quantization", "noise"}));
  EXPECT_EQ(active[3].parameters.size(), 3U);  // only the non-zero harmonics
}

/// Applies a bad spec and checks the message names what is wrong; config unchanged.
void expect_error(std::string_view spec, std::initializer_list<std::string_view> must_mention) {
  SensorChainConfig c;
  c.amplitude_imbalance.alpha = 0.5e-3;
  const auto err = apply_effect_spec(c, spec);
  ASSERT_TRUE(err.has_value()) << spec;
  for (std::string_view word : must_mention) EXPECT_NE(err->find(word), std::string::npos) << *err;
  EXPECT_DOUBLE_EQ(c.amplitude_imbalance.alpha, 0.5e-3) << "a failed spec must not change the config";
  EXPECT_DOUBLE_EQ(c.offsets.o_s, 0.0) << "a failed spec must not change the config";
}

TEST(EffectsCatalog, BadSpecsSayWhatIsWrong) {
  expect_error("amplitude_imbalanse:alpha=0.1", {"amplitude_imbalanse", "amplitude_imbalance", "quadrature"});
  expect_error("amplitude_imbalance:alfa=0.1", {"alfa", "alpha"});
  expect_error("amplitude_imbalance:alpha=abc", {"alpha", "abc"});
  expect_error("amplitude_imbalance:alpha=0.1x", {"alpha"});
  expect_error("amplitude_imbalance:alpha=2", {"alpha", "0.5"});
  expect_error("amplitude_imbalance", {"no parameters", "alpha"});
  expect_error("amplitude_imbalance:alpha", {"param=value"});
  expect_error("offsets:o_s=0.01,o_c=oops", {"o_c", "oops"});  // the good o_s is not applied either
  expect_error("quantization:rd_bits=12.5", {"rd_bits", "integer"});
  expect_error("quantization:rd_bits=17", {"rd_bits", "16"});
  expect_error("eccentricity:e=0.001", {"eccentricity", "not implemented"});
  expect_error("harmonics:k1=0.1", {"k1", "k0"});
}

TEST(EffectsCatalog, ListingShowsEveryEffect) {
  const std::string text = format_effect_catalog();
  for (const EffectInfo& e : effect_catalog()) EXPECT_NE(text.find(e.name), std::string::npos) << e.name;
  EXPECT_NE(text.find("omega_n"), std::string::npos);
  EXPECT_NE(text.find("[rad/s]"), std::string::npos);
  EXPECT_NE(text.find("not implemented yet"), std::string::npos);
}

}  // namespace
}  // namespace resolver
