#include <gtest/gtest.h>

#include <string>

#include "daemon/core/effects/registry.h"
#include "tools/sim/sim_truth.h"

namespace resolver {
namespace {

TEST(SimTruth, RecordsConfigurationAndActiveEffects) {
  SimConfig c;
  c.profile = {{5.0, 200.0, 200.0}, {3.0, 200.0, 1000.0}};
  c.seed = 42;
  c.iface = "vc\"an0";
  c.chain.apply_spec("amplitude_imbalance:alpha=0.003");
  c.chain.apply_spec("harmonics:k3=0.0005,k3_opp=-0.0002");
  c.chain.apply_spec("mechanical_harmonics:b2=1e-4");
  c.chain.apply_spec("delay:d=0.002");
  c.chain.apply_spec("backlash:h=0.01");
  c.chain.apply_spec("channel_delay:tau=3e-6");
  c.chain.apply_spec("outliers:rate=5,size=3000");
  const std::string json = sim_truth_json(c, 16000, "a.log");
  for (const char* expected :
       {"\"seed\": 42", "\"samples\": 16000", "\"p_r\": 3", "\"log\": \"a.log\"", "\"iface\": \"vc\\\"an0\"",
        "{\"duration_s\": 3, \"rpm_start\": 200, \"rpm_end\": 1000}", "\"amplitude_imbalance\": {\"alpha\": 0.003}",
        "\"harmonics\": {\"k3\": 0.0005, \"k3_opp\": -0.0002}", "\"tracking_loop\": {\"omega_n\": 3000, \"zeta\": 0.7}",
        "\"noise\": {\"sigma_sc\": 2, \"sigma_i\": 0.02}", "\"quadrature\": {\"beta\": 0}",
        "\"mechanical_harmonics\": {\"b2\": 0.0001}", "\"delay\": {\"d\": 0.002}", "\"backlash\": {\"h\": 0.01}",
        "\"channel_delay\": {\"tau\": 3e-06}", "\"outliers\": {\"rate\": 5, \"size\": 3000}"}) {
    EXPECT_NE(json.find(expected), std::string::npos) << expected << "\n" << json;
  }
  // Inactive effects appear only under "chain", not under "effects".
  const std::size_t effects = json.find("\"effects\"");
  const std::size_t chain = json.find("\"chain\"");
  ASSERT_LT(effects, chain);
  const std::string active_part = json.substr(effects, chain - effects);
  EXPECT_EQ(active_part.find("quadrature"), std::string::npos);
  EXPECT_EQ(active_part.find("eccentricity"), std::string::npos);
  // The chain part lists every registry effect, active or not, with all its parameters.
  const std::string chain_part = json.substr(chain);
  for (const Effect* e : effect_registry()) {
    EXPECT_NE(chain_part.find("\"" + std::string(e->name()) + "\": {\"" + std::string(e->params().front().name) + "\": "),
              std::string::npos)
        << e->name();
  }
  EXPECT_NE(chain_part.find("\"k20_opp_q\": 0}"), std::string::npos) << "the chain lists the long effects in full";
  // Braces and brackets balance (outside strings there are no others).
  int depth = 0;
  bool in_string = false;
  for (std::size_t i = 0; i < json.size(); ++i) {
    const char ch = json[i];
    if (in_string) {
      if (ch == '\\') ++i;
      else if (ch == '"') in_string = false;
    } else if (ch == '"') {
      in_string = true;
    } else if (ch == '{' || ch == '[') {
      ++depth;
    } else if (ch == '}' || ch == ']') {
      --depth;
      ASSERT_GE(depth, 0);
    }
  }
  EXPECT_EQ(depth, 0);
  EXPECT_FALSE(in_string);
}

}  // namespace
}  // namespace resolver
