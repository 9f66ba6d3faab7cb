// Bytes from lcm-gen's encode() -> our JSON -> a strict JSON parser -> the
// values we put in.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <limits>
#include <random>
#include <string>

#include <echo_test/node_t.hpp>
#include <generated_resolver_types.h>
#include <resolver/angle_t.hpp>
#include <resolver/dq_t.hpp>
#include <resolver/estimate_t.hpp>
#include <resolver/model_fit_t.hpp>

#include "echo_test_util.h"
#include "json_test_parser.h"
#include "tools/echo/echo_output.h"
#include "drivers/text/json_string.h"
#include "tools/echo/json_writer.h"
#include "tools/echo/lcm_json_decoder.h"

namespace resolver {
namespace {

using echo_test_support::encode;
using echo_test_support::Json;
using echo_test_support::parse_json;

const std::string kEchoTestTypes = RESOLVER_SOURCE_DIR "/tests/unit/echo/lcm/echo_test";

class EchoDecoder : public ::testing::Test {
 protected:
  EchoDecoder() : registry_(LcmTypeRegistry::with_embedded_types()), decoder_(registry_) {
    registry_.add_directory(kEchoTestTypes);
  }

  // The full JSON line, parsed back.
  Json line(const std::vector<std::uint8_t>& bytes, std::int64_t log_utime = 777) {
    const auto text = format_message_json(decoder_, EchoFilter{}, "CHAN", log_utime, bytes);
    EXPECT_TRUE(text.has_value());
    last_line_ = text.value_or("");
    return parse_json(last_line_);
  }

  LcmTypeRegistry registry_;
  LcmJsonDecoder decoder_;
  std::string last_line_;
};

TEST_F(EchoDecoder, AngleEveryFieldInDeclarationOrderNonFiniteAsNull) {
  resolver::angle_t m{};
  m.utime = 1'700'000'000'123'456;
  m.sample_index = 987'654'321'012;
  m.counter = -17;
  m.theta_rd = 0.1;
  m.theta_sincos = -2.5e-300;
  m.theta_comp = 6.283185307179586;
  m.theta_ref = std::numeric_limits<double>::quiet_NaN();
  m.speed_mech_rad_s = std::numeric_limits<double>::infinity();
  m.eps_hat = -std::numeric_limits<double>::infinity();
  m.eps_ref = 1e22;
  const Json j = line(encode(m));
  const std::vector<std::string> keys{"channel",      "type",      "utime",         "sample_index",
                                      "counter",      "theta_rd",  "theta_sincos",  "theta_comp",
                                      "theta_ref",    "speed_mech_rad_s", "eps_hat", "eps_ref"};
  EXPECT_EQ(j.keys(), keys) << last_line_;
  EXPECT_EQ(j["channel"].text, "CHAN");
  EXPECT_EQ(j["type"].text, "resolver.angle_t");
  EXPECT_EQ(j["utime"].integer(), m.utime);
  EXPECT_EQ(j["sample_index"].integer(), m.sample_index);
  EXPECT_EQ(j["counter"].integer(), m.counter);
  EXPECT_EQ(j["theta_rd"].number(), m.theta_rd);
  EXPECT_EQ(j["theta_sincos"].number(), m.theta_sincos);
  EXPECT_EQ(j["theta_comp"].number(), m.theta_comp);
  EXPECT_TRUE(j["theta_ref"].is_null());
  EXPECT_TRUE(j["speed_mech_rad_s"].is_null());
  EXPECT_TRUE(j["eps_hat"].is_null());
  EXPECT_EQ(j["eps_ref"].number(), m.eps_ref);
}

TEST_F(EchoDecoder, DqFixedArrays) {
  resolver::dq_t m{};
  m.utime = 5;
  m.ripple_order[0] = 1;
  m.ripple_order[1] = 2;
  m.ripple_order[2] = 6;
  for (int i = 0; i < 3; ++i) {
    m.i_d_ripple_raw[i] = 0.25 * i;
    m.i_q_ripple_ref[i] = -1.0 - i;
  }
  m.ripple_valid = true;
  const Json j = line(encode(m));
  ASSERT_EQ(j["ripple_order"].items.size(), 3u);
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(j["ripple_order"][i].integer(), m.ripple_order[i]);
    EXPECT_EQ(j["i_d_ripple_raw"][i].number(), m.i_d_ripple_raw[i]);
    EXPECT_EQ(j["i_q_ripple_ref"][i].number(), m.i_q_ripple_ref[i]);
  }
  EXPECT_TRUE(j["ripple_valid"].boolean);
  EXPECT_EQ(j["ripple_valid"].kind, Json::Kind::kBool);
}

TEST_F(EchoDecoder, EstimateVariableArraysAndEscapedStrings) {
  resolver::estimate_t m{};
  m.utime = 42;
  m.method = "quote\" backslash\\ newline\n tab\t ctl\x01 micro\xC2\xB5 end";
  m.num_params = 3;
  m.param_name = {"amplitude_imbalance.alpha", "", "x"};
  m.value = {0.01, -3.0, 1e-9};
  m.std_error = {std::nan(""), 0.5, 2.0};
  m.samples_used = 123456;
  m.revolutions_used = 12.5;
  m.converged = false;
  const Json j = line(encode(m));
  EXPECT_EQ(j["method"].text, m.method) << last_line_;
  EXPECT_EQ(last_line_.find('\n'), std::string::npos) << "one message, one line";
  EXPECT_EQ(j["num_params"].integer(), 3);
  ASSERT_EQ(j["param_name"].items.size(), 3u);
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(j["param_name"][i].text, m.param_name[i]);
    EXPECT_EQ(j["value"][i].number(), m.value[i]);
  }
  EXPECT_TRUE(j["std_error"][0].is_null());
  EXPECT_EQ(j["std_error"][2].number(), 2.0);
  EXPECT_EQ(j["samples_used"].integer(), 123456);
  EXPECT_EQ(j["revolutions_used"].number(), 12.5);
  EXPECT_FALSE(j["converged"].boolean);
}

TEST_F(EchoDecoder, ModelFitEmptyVariableArrays) {
  resolver::model_fit_t m{};
  m.utime = 9;
  m.verdict = "insufficient_data";
  const Json j = line(encode(m));
  EXPECT_EQ(j["effects"].kind, Json::Kind::kArray);
  EXPECT_TRUE(j["effects"].items.empty());
  EXPECT_TRUE(j["candidate_reason"].items.empty());
  EXPECT_EQ(j["verdict"].text, "insufficient_data");
}

TEST_F(EchoDecoder, EveryProtoTypeDecodesDefaultMessage) {
  for (const auto& g : echo_test_support::generated_resolver_types()) {
    SCOPED_TRACE(g.name);
    const DecodedMessage d = decoder_.decode(g.encode_default());
    EXPECT_EQ(d.error, "");
    ASSERT_NE(d.type, nullptr);
    EXPECT_EQ(d.type->full_name(), g.name);
    EXPECT_EQ(d.utime_json, "0");
  }
}

echo_test::leaf_t make_leaf(int seed) {
  echo_test::leaf_t l{};
  l.a = static_cast<int8_t>(-128 + seed);
  l.b = static_cast<int16_t>(-32768 + seed);
  l.c = std::numeric_limits<int32_t>::min() + seed;
  l.d = std::numeric_limits<int64_t>::min() + seed;
  l.f = 0.1f * static_cast<float>(seed + 1);
  l.g = -0.0;
  l.s = "leaf " + std::to_string(seed);
  l.flag = seed % 2 == 0;
  l.raw = static_cast<uint8_t>(200 + seed);
  l.rows = 2;
  l.cols = 3;
  l.grid.assign(2, std::vector<double>(3));
  for (int r = 0; r < 2; ++r) {
    for (int c = 0; c < 3; ++c) l.grid[r][c] = r * 10 + c + seed;
  }
  for (int r = 0; r < 2; ++r) {
    for (int c = 0; c < 3; ++c) l.fixed[r][c] = static_cast<int16_t>(100 * r + c);
  }
  l.blob = {0, 255, static_cast<uint8_t>(seed)};
  l.names[0] = "n0";
  l.names[1] = "";
  return l;
}

void expect_leaf(const Json& j, const echo_test::leaf_t& l) {
  EXPECT_EQ(j["a"].integer(), l.a);
  EXPECT_EQ(j["b"].integer(), l.b);
  EXPECT_EQ(j["c"].integer(), l.c);
  EXPECT_EQ(j["d"].integer(), l.d);
  EXPECT_EQ(std::strtof(j["f"].text.c_str(), nullptr), l.f) << "float prints shortest for float, not double";
  EXPECT_TRUE(std::signbit(j["g"].number()));
  EXPECT_EQ(j["s"].text, l.s);
  EXPECT_EQ(j["flag"].boolean, l.flag != 0);
  EXPECT_EQ(j["raw"].integer(), l.raw);
  ASSERT_EQ(j["grid"].items.size(), 2u);
  for (std::size_t r = 0; r < 2; ++r) {
    ASSERT_EQ(j["grid"][r].items.size(), 3u);
    for (std::size_t c = 0; c < 3; ++c) {
      EXPECT_EQ(j["grid"][r][c].number(), l.grid[r][c]);
      EXPECT_EQ(j["fixed"][r][c].integer(), l.fixed[r][c]);
    }
  }
  ASSERT_EQ(j["blob"].items.size(), 3u);
  for (std::size_t i = 0; i < 3; ++i) EXPECT_EQ(j["blob"][i].integer(), l.blob[i]);
  EXPECT_EQ(j["names"][0].text, l.names[0]);
  EXPECT_EQ(j["names"][1].text, l.names[1]);
  EXPECT_FALSE(j.has("MAX_ROWS")) << "consts are not encoded";
}

TEST_F(EchoDecoder, NestedRecursiveMultiDimensional) {
  echo_test::node_t m{};
  m.utime = -5;
  m.first = make_leaf(1);
  m.n = 2;
  m.more = {make_leaf(2), make_leaf(3)};
  m.tree.value = 1;
  m.tree.num_children = 2;
  m.tree.children.resize(2);
  m.tree.children[0].value = 2;
  m.tree.children[1].value = 3;
  m.tree.children[1].num_children = 1;
  m.tree.children[1].children.resize(1);
  m.tree.children[1].children[0].value = 4;
  m.pair[0] = make_leaf(4);
  m.pair[1] = make_leaf(5);

  const Json j = line(encode(m));
  EXPECT_EQ(j["type"].text, "echo_test.node_t");
  EXPECT_EQ(j["utime"].integer(), -5);
  expect_leaf(j["first"], m.first);
  ASSERT_EQ(j["more"].items.size(), 2u);
  expect_leaf(j["more"][0], m.more[0]);
  expect_leaf(j["more"][1], m.more[1]);
  expect_leaf(j["pair"][1], m.pair[1]);
  EXPECT_EQ(j["tree"]["value"].integer(), 1);
  EXPECT_EQ(j["tree"]["children"][1]["children"][0]["value"].integer(), 4);
  EXPECT_TRUE(j["tree"]["children"][1]["children"][0]["children"].items.empty());
  EXPECT_TRUE(j["tree"]["children"][0]["children"].items.empty());
}

TEST_F(EchoDecoder, TypeWithoutUtimeUsesTheLogTime) {
  const Json j = line(encode(make_leaf(0)), 31337);
  EXPECT_EQ(j["type"].text, "echo_test.leaf_t");
  EXPECT_EQ(j["utime"].integer(), 31337);
}

TEST_F(EchoDecoder, DoublesAndFloatsRoundTripExactly) {
  std::mt19937_64 rng(20240501);
  for (int i = 0; i < 2000; ++i) {
    resolver::angle_t m{};
    do {
      m.theta_rd = std::bit_cast<double>(rng());
    } while (!std::isfinite(m.theta_rd));
    echo_test::leaf_t l = make_leaf(0);
    do {
      l.f = std::bit_cast<float>(static_cast<std::uint32_t>(rng()));
    } while (!std::isfinite(l.f));
    const Json ja = line(encode(m));
    ASSERT_EQ(std::bit_cast<std::uint64_t>(ja["theta_rd"].number()), std::bit_cast<std::uint64_t>(m.theta_rd))
        << ja["theta_rd"].text;
    const Json jl = line(encode(l));
    ASSERT_EQ(std::bit_cast<std::uint32_t>(std::strtof(jl["f"].text.c_str(), nullptr)),
              std::bit_cast<std::uint32_t>(l.f))
        << jl["f"].text;
  }
}

TEST_F(EchoDecoder, EveryTruncationIsAnErrorNeverACrash) {
  echo_test::node_t m{};
  m.first = make_leaf(1);
  m.n = 1;
  m.more = {make_leaf(2)};
  const auto full = encode(m);
  ASSERT_EQ(decoder_.decode(full).error, "");
  for (std::size_t len = 0; len < full.size(); ++len) {
    const std::span<const std::uint8_t> cut(full.data(), len);
    const DecodedMessage d = decoder_.decode(cut);
    ASSERT_FALSE(d.error.empty()) << "length " << len;
    if (len >= 8) {
      EXPECT_NE(d.error.find("echo_test.node_t"), std::string::npos) << d.error;
      EXPECT_NE(d.error.find("byte offset"), std::string::npos) << d.error;
    }
    // The line is still valid JSON with the error in it.
    const Json j = line(std::vector<std::uint8_t>(cut.begin(), cut.end()));
    EXPECT_TRUE(j["utime"].is_null());
    EXPECT_EQ(j["size"].integer(), static_cast<long long>(len));
    EXPECT_EQ(j["error"].text, d.error);
  }
}

TEST_F(EchoDecoder, RandomlyCorruptedBytesGiveValidJsonNeverACrash) {
  echo_test::node_t m{};
  m.first = make_leaf(1);
  m.n = 2;
  m.more = {make_leaf(2), make_leaf(3)};
  m.tree.num_children = 1;
  m.tree.children.resize(1);
  const auto good = encode(m);
  std::mt19937 rng(7);
  std::uniform_int_distribution<std::size_t> where(8, good.size() - 1);  // keep the fingerprint
  int errors = 0;
  for (int i = 0; i < 3000; ++i) {
    auto bytes = good;
    for (int k = 0; k < 3; ++k) bytes[where(rng)] = static_cast<std::uint8_t>(rng());
    const Json j = line(bytes);
    EXPECT_EQ(j["type"].text, "echo_test.node_t");
    errors += j.has("error") ? 1 : 0;
  }
  // Most corruptions hit values (still decodable); some hit lengths.
  EXPECT_GT(errors, 0);
  EXPECT_LT(errors, 3000);
}

TEST_F(EchoDecoder, TruncationErrorNamesTheMemberPath) {
  echo_test::node_t m{};
  m.n = 1;
  m.more = {make_leaf(2)};
  auto bytes = encode(m);
  // Cut inside more[0].grid[1][2]; row grid[1] no longer fits: hash, utime, first, n, then more[0]'s 48 bytes
  // before grid (a b c d f g s="leaf 2" flag raw rows cols) and 5.5 of its doubles.
  const auto first_size = static_cast<std::size_t>(m.first._getEncodedSizeNoHash());
  const std::size_t leaf_head = 1 + 2 + 4 + 8 + 4 + 8 + (4 + 6 + 1) + 1 + 1 + 4 + 4;
  bytes.resize(8 + 8 + first_size + 1 + leaf_head + 5 * 8 + 4);
  const DecodedMessage d = decoder_.decode(bytes);
  EXPECT_NE(d.error.find("member 'more[0].grid[1]' of echo_test.node_t"), std::string::npos) << d.error;
}

TEST_F(EchoDecoder, CorruptLengthsAreErrors) {
  resolver::estimate_t m{};
  m.method = "m";
  m.num_params = 1;
  m.param_name = {"p"};
  m.value = {1.0};
  m.std_error = {2.0};
  auto bytes = encode(m);
  // num_params follows hash, utime, sample_index, counter and method ("m": 4 + 2 bytes).
  const std::size_t at = 8 + 8 + 8 + 2 + 4 + 2;
  ASSERT_EQ(bytes[at + 3], 1);
  bytes[at] = 0xFF;  // -> a negative count
  EXPECT_NE(decoder_.decode(bytes).error.find("negative"), std::string::npos) << decoder_.decode(bytes).error;
  bytes[at] = 0x7F;  // -> two billion strings in a few bytes
  EXPECT_NE(decoder_.decode(bytes).error.find("truncated or corrupt"), std::string::npos)
      << decoder_.decode(bytes).error;
  bytes[at] = 0;
  bytes[8 + 8 + 8 + 2 + 3] = 0;  // method's string length 2 -> 0
  EXPECT_NE(decoder_.decode(bytes).error.find("string length 0"), std::string::npos) << decoder_.decode(bytes).error;
}

TEST_F(EchoDecoder, UnknownFingerprintIsReportedWithItsValue) {
  resolver::angle_t m{};
  auto bytes = encode(m);
  bytes[0] ^= 0x80;
  std::uint64_t fp = 0;
  for (int i = 0; i < 8; ++i) fp = (fp << 8) | bytes[static_cast<std::size_t>(i)];
  const Json j = line(bytes);
  EXPECT_TRUE(j["type"].is_null());
  EXPECT_TRUE(j["utime"].is_null());
  EXPECT_EQ(j["size"].integer(), static_cast<long long>(bytes.size()));
  EXPECT_EQ(j["error"].text, "unknown fingerprint " + hex64(fp));
}

TEST(EchoJsonWriter, InvalidUtf8BecomesReplacementCharacter) {
  std::string out;
  text::append_json_string(out, std::string("a\xFF" "b\xC3" "\xA9" "\xE2\x82", 7));
  EXPECT_EQ(out, "\"a\\ufffdb\xC3\xA9\\ufffd\\ufffd\"");
  EXPECT_NO_THROW(parse_json(out));
}

}  // namespace
}  // namespace resolver
