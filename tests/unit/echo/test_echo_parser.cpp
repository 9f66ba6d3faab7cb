// .lcm parsing: structure of the parsed types and the quality of the errors.
#include <gtest/gtest.h>

#include <string>

#include "tools/echo/embedded_lcm_types.h"
#include "tools/echo/lcm_type_parser.h"

namespace resolver {
namespace {

TEST(EchoParser, ReadsMembersConstsArraysAndComments) {
  const auto structs = parse_lcm_types(R"(
    // line comment
    package pk;   /* block
                     comment */
    struct a_t {
      const int32_t N = 4, M = -2;  /// doc
      const double PI = 3.14;
      int64_t utime;
      int32_t rows, cols;
      double grid[rows][3];
      other_t child;
      pk2.far_t far[cols];
      string s;
    }
    struct b_t { boolean ok; }
  )", "mem.lcm");
  ASSERT_EQ(structs.size(), 2u);
  const LcmStruct& a = structs[0];
  EXPECT_EQ(a.full_name(), "pk.a_t");
  EXPECT_EQ(a.source, "mem.lcm:5");
  ASSERT_EQ(a.constants.size(), 3u);
  EXPECT_EQ(a.constants[1].name, "M");
  EXPECT_EQ(a.constants[1].value_text, "-2");
  EXPECT_EQ(a.constants[2].type_name, "double");
  ASSERT_EQ(a.members.size(), 7u);
  EXPECT_EQ(a.members[1].name, "rows");
  EXPECT_EQ(a.members[2].name, "cols");
  EXPECT_EQ(a.members[2].primitive, LcmPrimitive::kInt32);
  const LcmMember& grid = a.members[3];
  ASSERT_EQ(grid.dimensions.size(), 2u);
  EXPECT_TRUE(grid.dimensions[0].is_variable);
  EXPECT_EQ(grid.dimensions[0].size_text, "rows");
  EXPECT_FALSE(grid.dimensions[1].is_variable);
  EXPECT_EQ(grid.dimensions[1].fixed_size, 3);
  // Bare struct names get the file's package; qualified names stay as written.
  EXPECT_EQ(a.members[4].type_name, "pk.other_t");
  EXPECT_FALSE(a.members[4].primitive.has_value());
  EXPECT_EQ(a.members[5].type_name, "pk2.far_t");
  EXPECT_EQ(a.members[6].primitive, LcmPrimitive::kString);
  EXPECT_EQ(structs[1].full_name(), "pk.b_t");
}

TEST(EchoParser, HexArraySizeKeepsItsText) {
  const auto structs = parse_lcm_types("struct x_t { byte b[0x10]; }", "x.lcm");
  ASSERT_EQ(structs.size(), 1u);
  EXPECT_EQ(structs[0].full_name(), "x_t");  // no package
  EXPECT_EQ(structs[0].members[0].dimensions[0].fixed_size, 16);
  EXPECT_EQ(structs[0].members[0].dimensions[0].size_text, "0x10");
}

struct BadCase {
  const char* text;
  const char* location;  // "file:line:col" the message must start with
  const char* hint;      // a phrase the message must contain
};

class EchoParserErrors : public ::testing::TestWithParam<BadCase> {};

TEST_P(EchoParserErrors, NameFileLineColumnAndProblem) {
  const BadCase& c = GetParam();
  try {
    parse_lcm_types(c.text, "bad.lcm");
    FAIL() << "no error for: " << c.text;
  } catch (const LcmParseError& e) {
    const std::string msg = e.what();
    EXPECT_EQ(msg.rfind(c.location, 0), 0u) << msg;
    EXPECT_NE(msg.find(c.hint), std::string::npos) << msg;
  }
}

INSTANTIATE_TEST_SUITE_P(
    Cases, EchoParserErrors,
    ::testing::Values(
        BadCase{"struct a { double x[n]; }", "bad.lcm:1:21:", "declared earlier"},
        BadCase{"struct a { double n; int8_t x[n]; }", "bad.lcm:1:31:", "must be a scalar int8_t"},
        BadCase{"struct a { int8_t x[0]; }", "bad.lcm:1:21:", "positive integer"},
        BadCase{"struct a {\n  int8_t x\n}", "bad.lcm:3:1:", "expected ';'"},
        BadCase{"struct a { int8_t x; int16_t x; }", "bad.lcm:1:30:", "used twice"},
        BadCase{"struct a { int8_t x; /* never closed }", "bad.lcm:1:22:", "never closed"},
        BadCase{"struct a { int8_t x;", "bad.lcm:1:20:", "file ends"},
        BadCase{"enum e { A, B }", "bad.lcm:1:1:", "enums are not supported"},
        BadCase{"message a { }", "bad.lcm:1:1:", "expected 'package' or 'struct'"},
        BadCase{"struct a { const string S = 1; }", "bad.lcm:1:18:", "cannot be a const type"},
        BadCase{"struct a { const int8_t S = 300; }", "bad.lcm:1:29:", "out of range"},
        BadCase{"struct a { const double S = abc; }", "bad.lcm:1:29:", "not a floating-point"},
        BadCase{"struct a { struct b { } }", "bad.lcm:1:12:", "nested 'struct'"},
        BadCase{"struct a { int8_t 9x; }", "bad.lcm:1:19:", "not a valid member name"},
        BadCase{"struct a { } struct a { }", "bad.lcm:1:14:", "defined twice"}));

TEST(EchoParser, EveryEmbeddedProtoFileParses) {
  ASSERT_FALSE(embedded_lcm_files().empty());
  for (const auto& file : embedded_lcm_files()) {
    SCOPED_TRACE(std::string(file.path));
    std::vector<LcmStruct> structs;
    ASSERT_NO_THROW(structs = parse_lcm_types(file.text, file.path));
    ASSERT_EQ(structs.size(), 1u);
    EXPECT_EQ(structs[0].package, "resolver");
    // docs/ARCHITECTURE.md §4: every message has int64_t utime.
    const LcmMember* utime = structs[0].find_member("utime");
    ASSERT_NE(utime, nullptr);
    EXPECT_EQ(utime->primitive, LcmPrimitive::kInt64);
  }
}

}  // namespace
}  // namespace resolver
