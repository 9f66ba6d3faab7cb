#include <gtest/gtest.h>

#include <string>

#include "daemon/core/effects/effect_catalog.h"
#include "tools/sim/sim_truth.h"

namespace resolver {
namespace {

TEST(SimTruth, RecordsConfigurationAndActiveEffects) {
  SimConfig c;
  c.profile = {{5.0, 200.0, 200.0}, {3.0, 200.0, 1000.0}};
  c.seed = 42;
  c.iface = "vc\"an0";
  ASSERT_FALSE(apply_effect_spec(c.chain, "amplitude_imbalance:alpha=0.003"));
  ASSERT_FALSE(apply_effect_spec(c.chain, "harmonics:k3=0.0005"));
  const std::string json = sim_truth_json(c, 16000, "a.log");
  for (const char* expected :
       {"\"seed\": 42", "\"samples\": 16000", "\"p_r\": 3", "\"log\": \"a.log\"", "\"iface\": \"vc\\\"an0\"",
        "{\"duration_s\": 3, \"rpm_start\": 200, \"rpm_end\": 1000}", "\"amplitude_imbalance\": {\"alpha\": 0.003}",
        "\"harmonics\": {\"k3\": 0.0005}", "\"tracking_loop\": {\"omega_n\": 3000, \"zeta\": 0.7}",
        "\"noise\": {\"sigma_sc\": 2, \"sigma_i\": 0.02}", "\"quadrature\": {\"beta\": 0}"}) {
    EXPECT_NE(json.find(expected), std::string::npos) << expected << "\n" << json;
  }
  // Inactive effects appear only under "chain", not under "effects".
  const std::size_t effects = json.find("\"effects\"");
  const std::size_t chain = json.find("\"chain\"");
  ASSERT_LT(effects, chain);
  const std::string active_part = json.substr(effects, chain - effects);
  EXPECT_EQ(active_part.find("quadrature"), std::string::npos);
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
