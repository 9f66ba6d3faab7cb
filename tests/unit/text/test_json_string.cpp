// The one JSON string writer (drivers/text/json_string.h): every control
// character escaped, nothing dropped, UTF-8 passed through, ordinary text as is.
#include "drivers/text/json_string.h"

#include <gtest/gtest.h>

#include <string>

namespace resolver::text {
namespace {

TEST(JsonString, OrdinaryTextIsQuotedUnchanged) {
  EXPECT_EQ(json_string(""), "\"\"");
  EXPECT_EQ(json_string("amplitude_imbalance: 2theta, +-1/2 LSB [rad]"),
            "\"amplitude_imbalance: 2theta, +-1/2 LSB [rad]\"");
}

TEST(JsonString, QuotesAndBackslashes) {
  EXPECT_EQ(json_string("say \"hi\""), "\"say \\\"hi\\\"\"");
  EXPECT_EQ(json_string("C:\\logs\\a.log"), "\"C:\\\\logs\\\\a.log\"");
  EXPECT_EQ(json_string("/"), "\"/\"");  // the solidus needs no escape
}

TEST(JsonString, ShortFormsForCommonControlCharacters) {
  EXPECT_EQ(json_string("a\nb\rc\td\be\ff"), "\"a\\nb\\rc\\td\\be\\ff\"");
}

TEST(JsonString, EveryOtherControlCharacterIsEscapedNeverDropped) {
  for (int c = 0; c < 0x20; ++c) {
    const std::string in(1, static_cast<char>(c));
    const std::string out = json_string(in);
    ASSERT_GE(out.size(), 4u) << "control character " << c << " dropped";
    for (const char ch : out) EXPECT_GE(static_cast<unsigned char>(ch), 0x20) << "raw control in output for " << c;
  }
  EXPECT_EQ(json_string(std::string("a\0b", 3)), "\"a\\u0000b\"");
  EXPECT_EQ(json_string("\x01\x1f"), "\"\\u0001\\u001f\"");
  EXPECT_EQ(json_string("\x1b[0m"), "\"\\u001b[0m\"");
  EXPECT_EQ(json_string("\x7f"), "\"\\u007f\"");
}

TEST(JsonString, Utf8PassesThrough) {
  const std::string text = "\xCE\xB8 = 30\xC2\xB0, \xE2\x82\xAC, \xF0\x9F\x99\x82";  // theta, degree, euro, emoji
  EXPECT_EQ(json_string(text), "\"" + text + "\"");
}

TEST(JsonString, InvalidUtf8BecomesOneReplacementPerByte) {
  EXPECT_EQ(json_string(std::string("a\xFF" "b\xC3" "\xA9" "\xE2\x82", 7)), "\"a\\ufffdb\xC3\xA9\\ufffd\\ufffd\"");
  EXPECT_EQ(json_string("\xC0\xAF"), "\"\\ufffd\\ufffd\"");          // overlong '/'
  EXPECT_EQ(json_string("\xED\xA0\x80"), "\"\\ufffd\\ufffd\\ufffd\"");  // a surrogate
}

TEST(JsonString, ScriptSafeEscapesMarkupCharactersOnly) {
  EXPECT_EQ(json_string("</script><b>&", JsonEscape::script_safe), "\"\\u003c/script\\u003e\\u003cb\\u003e\\u0026\"");
  EXPECT_EQ(json_string("</script>&"), "\"</script>&\"");
  EXPECT_EQ(json_string("x\n\"y\"", JsonEscape::script_safe), "\"x\\n\\\"y\\\"\"");
}

TEST(JsonString, AppendsToWhatIsThere) {
  std::string out = "{\"k\":";
  append_json_string(out, "v\t");
  EXPECT_EQ(out, "{\"k\":\"v\\t\"");
}

}  // namespace
}  // namespace resolver::text
