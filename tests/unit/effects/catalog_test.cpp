#include <gtest/gtest.h>

#include <cstdio>
#include <set>
#include <string>

#include "daemon/core/effects/effect_catalog.h"

namespace resolver {
namespace {

/// "effect:param=value" with the value printed to round-trip.
std::string fmt_spec(std::string_view effect, std::string_view param, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return std::string(effect) + ":" + std::string(param) + "=" + buf;
}

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
  EXPECT_FALSE(apply_effect_spec(c, "sampling_skew:tau=2e-6"));
  EXPECT_FALSE(apply_effect_spec(c, "eccentricity:e=5e-4,phase=1.2"));
  EXPECT_FALSE(apply_effect_spec(c, "mounting_offset:theta_0=-0.05"));
  EXPECT_FALSE(apply_effect_spec(c, "current_offsets:off_a=0.05,off_b=-0.03"));
  EXPECT_FALSE(apply_effect_spec(c, "current_gain_mismatch:gain_a=0.01,gain_b=-0.005"));
  EXPECT_FALSE(apply_effect_spec(c, "dead_time:t_d=2e-6"));
  EXPECT_DOUBLE_EQ(c.sampling_skew.tau, 2e-6);
  EXPECT_DOUBLE_EQ(c.eccentricity.e, 5e-4);
  EXPECT_DOUBLE_EQ(c.eccentricity.phase, 1.2);
  EXPECT_DOUBLE_EQ(c.mounting_offset.theta_0, -0.05);
  EXPECT_DOUBLE_EQ(c.current_offsets.off_a, 0.05);
  EXPECT_DOUBLE_EQ(c.current_offsets.off_b, -0.03);
  EXPECT_DOUBLE_EQ(c.current_gain_mismatch.gain_a, 0.01);
  EXPECT_DOUBLE_EQ(c.current_gain_mismatch.gain_b, -0.005);
  EXPECT_DOUBLE_EQ(c.dead_time.t_d, 2e-6);

  const std::vector<EffectValues> active = active_effect_values(c);
  std::vector<std::string_view> names;
  for (const EffectValues& v : active) names.push_back(v.effect);
  EXPECT_EQ(names, (std::vector<std::string_view>{"amplitude_imbalance", "quadrature", "offsets", "harmonics",
                                                  "sampling_skew", "tracking_loop", "quantization", "eccentricity",
                                                  "mounting_offset", "current_offsets", "current_gain_mismatch",
                                                  "dead_time", "noise"}));
  EXPECT_EQ(active[3].parameters.size(), 3U);  // only the non-zero harmonics
  EXPECT_EQ(active[7].parameters.size(), 2U);  // eccentricity: e and phase
}

TEST(EffectsCatalog, EveryParameterRoundTripsThroughItsSetterAndGetter) {
  for (const EffectInfo& e : effect_catalog()) {
    ASSERT_TRUE(e.implemented) << e.name << ": catalog v2 implements every DESIGN 6 effect";
    for (const EffectParameter& p : e.parameters) {
      SensorChainConfig c;
      // A value inside the range and different from the default (integers: the minimum).
      const double v = p.integer ? p.min : p.min + 0.25 * (p.max - p.min);
      ASSERT_NE(p.get(c), v) << p.name;
      const auto err = apply_effect_spec(c, fmt_spec(e.name, p.name, v));
      ASSERT_FALSE(err.has_value()) << *err;
      EXPECT_EQ(p.get(c), v) << e.name << ":" << p.name;
    }
  }
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
  expect_error("sampling_skew:tau=0.01", {"tau", "[s]"});
  expect_error("eccentricity:e=0.6", {"eccentricity", "'e'"});
  expect_error("eccentricity:ee=0.001", {"ee", "e, phase"});
  expect_error("mounting_offset:theta_0=4", {"theta_0", "[rad]"});
  expect_error("current_offsets:off_c=0.1", {"off_c", "off_a, off_b"});
  expect_error("current_gain_mismatch:gain_a=-0.7", {"gain_a"});
  expect_error("dead_time:t_d=-1e-6", {"t_d", "[s]"});
  expect_error("harmonics:k1=0.1", {"k1", "k0"});
}

TEST(EffectsCatalog, ListingShowsEveryEffect) {
  const std::string text = format_effect_catalog();
  for (const EffectInfo& e : effect_catalog()) EXPECT_NE(text.find(e.name), std::string::npos) << e.name;
  EXPECT_NE(text.find("omega_n"), std::string::npos);
  EXPECT_NE(text.find("[rad/s]"), std::string::npos);
  EXPECT_EQ(text.find("not implemented yet"), std::string::npos);
  EXPECT_NE(text.find("sampling_skew"), std::string::npos);
  EXPECT_NE(text.find("theta_0"), std::string::npos);
}

}  // namespace
}  // namespace resolver
