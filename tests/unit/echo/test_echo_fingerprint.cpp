// Fingerprints must equal lcm-gen's getHash(): that is how a message finds its type.
#include <gtest/gtest.h>

#include <filesystem>
#include <set>

#include <echo_test/node_t.hpp>
#include <generated_resolver_types.h>

#include "tools/echo/lcm_fingerprint.h"
#include "tools/echo/lcm_type_parser.h"
#include "tools/echo/lcm_type_registry.h"

namespace resolver {
namespace {

const std::string kEchoTestTypes = RESOLVER_SOURCE_DIR "/tests/unit/echo/lcm/echo_test";

TEST(EchoFingerprint, EveryProtoTypeMatchesLcmGen) {
  const auto registry = LcmTypeRegistry::with_embedded_types();
  EXPECT_TRUE(registry.problems().empty());
  const auto generated = echo_test_support::generated_resolver_types();
  ASSERT_FALSE(generated.empty());
  for (const auto& g : generated) {
    SCOPED_TRACE(g.name);
    const auto fp = registry.fingerprint_of(g.name);
    ASSERT_TRUE(fp.has_value());
    EXPECT_EQ(*fp, static_cast<std::uint64_t>(g.hash));
    ASSERT_NE(registry.find_by_fingerprint(*fp), nullptr);
    EXPECT_EQ(registry.find_by_fingerprint(*fp)->full_name(), g.name);
  }
  // Nothing embedded that lcm-gen did not also see, and vice versa.
  EXPECT_EQ(registry.types().size(), generated.size());
}

TEST(EchoFingerprint, NestedRecursiveAndMultiDimensionalTypesMatchLcmGen) {
  LcmTypeRegistry registry;
  registry.add_directory(kEchoTestTypes);
  EXPECT_TRUE(registry.problems().empty());
  EXPECT_EQ(registry.fingerprint_of("echo_test.leaf_t"), static_cast<std::uint64_t>(echo_test::leaf_t::getHash()));
  EXPECT_EQ(registry.fingerprint_of("echo_test.tree_t"), static_cast<std::uint64_t>(echo_test::tree_t::getHash()));
  EXPECT_EQ(registry.fingerprint_of("echo_test.node_t"), static_cast<std::uint64_t>(echo_test::node_t::getHash()));
}

TEST(EchoFingerprint, StructNameAndConstsDoNotMatterMemberNamesAndTypesDo) {
  const auto hash_of = [](const std::string& text) {
    const auto structs = parse_lcm_types(text, "t.lcm");
    return lcm_fingerprint(structs.at(0), [](const std::string&) { return nullptr; });
  };
  const auto base = hash_of("struct a { int32_t n; double x[n]; }");
  EXPECT_EQ(base, hash_of("package p; struct renamed { const int8_t K = 1; int32_t n; double x[n]; }"));
  std::set<std::uint64_t> variants{base};
  variants.insert(hash_of("struct a { int32_t n; double y[n]; }"));
  variants.insert(hash_of("struct a { int32_t n; float x[n]; }"));
  variants.insert(hash_of("struct a { int64_t n; double x[n]; }"));
  variants.insert(hash_of("struct a { int32_t n; double x[3]; }"));
  variants.insert(hash_of("struct a { int32_t n; double x[n][2]; }"));
  variants.insert(hash_of("struct a { int32_t n; double x; }"));
  EXPECT_EQ(variants.size(), 7u) << "each change must change the fingerprint";
}

TEST(EchoFingerprint, MissingNestedTypeIsReportedNotGuessed) {
  LcmTypeRegistry registry;
  registry.add_text("package q; struct outer_t { int64_t utime; inner_t x; }", "outer.lcm");
  EXPECT_FALSE(registry.fingerprint_of("q.outer_t").has_value());
  ASSERT_EQ(registry.problems().size(), 1u);
  EXPECT_NE(registry.problems()[0].find("q.inner_t"), std::string::npos) << registry.problems()[0];
  EXPECT_NE(registry.problems()[0].find("outer.lcm:1"), std::string::npos) << registry.problems()[0];
  // Adding the missing type later resolves it.
  registry.add_text("package q; struct inner_t { double v; }", "inner.lcm");
  EXPECT_TRUE(registry.fingerprint_of("q.outer_t").has_value());
  EXPECT_TRUE(registry.problems().empty());
}

TEST(EchoFingerprint, AddDirectoryErrorsNameTheDirectory) {
  LcmTypeRegistry registry;
  try {
    registry.add_directory("/nonexistent/echo/types");
    FAIL() << "no error";
  } catch (const LcmParseError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/echo/types"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace resolver
