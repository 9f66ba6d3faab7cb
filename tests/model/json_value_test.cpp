// The unit.json reader of resolver-model fleet --summarize (tools/model/json_value.h):
// strict JSON, whitespace included (a unit.json pretty-printed by another tool).
#include <gtest/gtest.h>

#include <stdexcept>

#include "tools/model/json_value.h"

namespace resolver::json {
namespace {

TEST(JsonValue, ReadsWhitespaceAroundEveryToken) {
  const Json j = parse_json(" {\n  \"a\" : [ 1 , 2.5e-3 ,\t\"x\" ] ,\r\n  \"b\": { } , \"c\" : [ ] , \"d\": null }\n");
  EXPECT_EQ(j["a"].items.size(), 3U);
  EXPECT_DOUBLE_EQ(j["a"][1].number(), 2.5e-3);
  EXPECT_EQ(j["a"][2].text, "x");
  EXPECT_TRUE(j["b"].members.empty());
  EXPECT_TRUE(j["c"].items.empty());
  EXPECT_TRUE(j["d"].is_null());
}

TEST(JsonValue, RefusesWhatIsNotJson) {
  EXPECT_THROW((void)parse_json("{\"a\": 1,}"), std::runtime_error);
  EXPECT_THROW((void)parse_json("{\"a\": 1} x"), std::runtime_error);
  EXPECT_THROW((void)parse_json("\"\\uZZZZ\""), std::runtime_error);  // not std::invalid_argument (a usage error)
  EXPECT_EQ(parse_json("\"\\u00e9\"").text, "\xc3\xa9");
}

}  // namespace
}  // namespace resolver::json
