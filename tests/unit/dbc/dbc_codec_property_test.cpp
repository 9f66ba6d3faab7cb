// Property test: the fast codec agrees bit for bit with the naive walker in
// naive_bit_codec.h for random signals, payloads and payload sizes, and
// insert_raw writes exactly the signal's bits.
#include <gtest/gtest.h>

#include <array>
#include <random>
#include <set>
#include <vector>

#include "daemon/dbc/dbc_codec.h"
#include "tests/unit/dbc/naive_bit_codec.h"

namespace resolver::dbc {
namespace {

constexpr int kCases = 20000;
constexpr std::uint32_t kMaxPayloadBits = 64 * 8;

struct Case {
  Signal signal;
  std::vector<std::uint8_t> data;
};

// A random signal anywhere in a 64-byte payload, and a payload of random size
// (so some signals run past its end, and the slow path gets exercised).
Case random_case(std::mt19937_64& rng) {
  Case c;
  Signal& s = c.signal;
  s.name = "x";
  s.length = std::uniform_int_distribution<std::uint32_t>(1, 64)(rng);
  s.order = (rng() & 1U) != 0 ? ByteOrder::kBigEndian : ByteOrder::kLittleEndian;
  s.is_signed = (rng() & 1U) != 0;
  // Position of the first bit along the signal's own direction of travel, so it fits in 64 bytes.
  const std::uint32_t first = std::uniform_int_distribution<std::uint32_t>(0, kMaxPayloadBits - s.length)(rng);
  // Motorola numbers the MSB of a byte 7: the first walked bit "first" lands at byte first/8, bit 7 - first%8.
  s.start_bit = s.order == ByteOrder::kLittleEndian ? first : (first / 8) * 8 + (7 - first % 8);
  // Half the cases use a full classic/FD-sized payload, the rest any size 0..64 bytes.
  const std::size_t sizes[] = {8, 64};
  const std::size_t size = (rng() & 1U) != 0 ? sizes[rng() % 2] : std::uniform_int_distribution<std::size_t>(0, 64)(rng);
  c.data.resize(size);
  for (auto& b : c.data) b = static_cast<std::uint8_t>(rng());
  return c;
}

std::uint64_t mask_of(std::uint32_t length) { return length >= 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << length) - 1; }

TEST(DbcCodecProperty, ExtractAgreesWithNaiveBitWalker) {
  std::mt19937_64 rng(0x5EED'DBC1);
  for (int i = 0; i < kCases; ++i) {
    const Case c = random_case(rng);
    const std::uint64_t expected = test::naive_extract(c.signal, c.data);
    ASSERT_EQ(extract_raw(c.signal, c.data), expected)
        << "case " << i << " start " << c.signal.start_bit << " len " << c.signal.length << " motorola "
        << (c.signal.order == ByteOrder::kBigEndian) << " size " << c.data.size();
    const std::int64_t expected_signed =
        c.signal.is_signed ? test::naive_sign_extend(expected, c.signal.length) : static_cast<std::int64_t>(expected);
    ASSERT_EQ(extract_signed(c.signal, c.data), expected_signed) << "case " << i;
  }
}

TEST(DbcCodecProperty, InsertRoundTripsAndLeavesOtherBitsAlone) {
  std::mt19937_64 rng(0x5EED'DBC2);
  for (int i = 0; i < kCases; ++i) {
    Case c = random_case(rng);
    const std::vector<std::uint8_t> before = c.data;
    const std::uint64_t value = rng();
    insert_raw(c.signal, value, c.data);

    const std::vector<std::uint64_t> bits = test::naive_bit_positions(c.signal);
    const std::set<std::uint64_t> own(bits.begin(), bits.end());
    for (std::uint64_t pos = 0; pos < 8 * c.data.size(); ++pos) {
      if (own.count(pos) != 0) continue;
      ASSERT_EQ(test::payload_bit(c.data, pos), test::payload_bit(before, pos)) << "case " << i << " disturbed bit " << pos;
    }
    // Bits of the signal inside the payload carry the value; those beyond it were dropped.
    std::uint64_t in_payload = 0;
    for (std::size_t k = 0; k < bits.size(); ++k) {
      if (bits[k] / 8 < c.data.size()) in_payload |= std::uint64_t{1} << k;
    }
    ASSERT_EQ(test::naive_extract(c.signal, c.data), value & mask_of(c.signal.length) & in_payload) << "case " << i;
    ASSERT_EQ(extract_raw(c.signal, c.data), value & mask_of(c.signal.length) & in_payload) << "case " << i;
  }
}

TEST(DbcCodecProperty, PhysicalIsRawTimesFactorPlusOffset) {
  std::mt19937_64 rng(0x5EED'DBC3);
  std::uniform_real_distribution<double> scale(-10.0, 10.0);
  for (int i = 0; i < 2000; ++i) {
    Case c = random_case(rng);
    c.signal.factor = scale(rng);
    c.signal.offset = scale(rng);
    const std::uint64_t raw = test::naive_extract(c.signal, c.data);
    const double raw_value = c.signal.is_signed ? static_cast<double>(test::naive_sign_extend(raw, c.signal.length))
                                                : static_cast<double>(raw);
    // Same two IEEE operations on the same inputs: the result must be identical.
    ASSERT_EQ(decode_physical(c.signal, c.data), raw_value * c.signal.factor + c.signal.offset) << "case " << i;
  }
}

// The two worked examples of the Motorola layout in the canmatrix byte-order
// notes: 7|32@0 is bytes 0..3 big endian; 3|11@0 is byte 0 bits 3..0 then byte 1 bits 7..1.
TEST(DbcCodecMotorola, MatchesPublishedLayoutExamples) {
  Signal s32;
  s32.order = ByteOrder::kBigEndian;
  s32.start_bit = 7;
  s32.length = 32;
  const std::array<std::uint8_t, 8> d{0x12, 0x34, 0x56, 0x78, 0x9A, 0xBC, 0xDE, 0xF0};
  EXPECT_EQ(extract_raw(s32, d), (std::uint64_t{d[0]} << 24) | (std::uint64_t{d[1]} << 16) | (std::uint64_t{d[2]} << 8) | d[3]);

  Signal s11;
  s11.order = ByteOrder::kBigEndian;
  s11.start_bit = 3;
  s11.length = 11;
  const std::uint64_t high4 = d[0] & 0x0FU;          // byte 0 bits 3..0 are the top 4 bits
  const std::uint64_t low7 = (d[1] >> 1U) & 0x7FU;   // byte 1 bits 7..1 are the low 7 bits
  EXPECT_EQ(extract_raw(s11, d), (high4 << 7U) | low7);
}

TEST(DbcCodecEdges, ZeroLengthAndFarAwaySignalsAreZeroAndDoNotWrite) {
  std::array<std::uint8_t, 8> d{};
  d.fill(0xA5);
  const std::array<std::uint8_t, 8> orig = d;
  Signal s;
  s.length = 0;
  EXPECT_EQ(extract_raw(s, d), 0U);
  insert_raw(s, ~std::uint64_t{0}, d);
  EXPECT_EQ(d, orig);
  for (ByteOrder order : {ByteOrder::kLittleEndian, ByteOrder::kBigEndian}) {
    Signal far;
    far.order = order;
    far.length = 64;
    far.start_bit = 0xFFFFFFF0U;  // billions of bits past any payload
    EXPECT_EQ(extract_raw(far, d), 0U);
    insert_raw(far, ~std::uint64_t{0}, d);
    EXPECT_EQ(d, orig);
  }
}

TEST(DbcCodecFloat, Float32And64SignalsDecodeTheirIeeeBits) {
  std::array<std::uint8_t, 16> d{};
  Signal f;
  f.value_type = ValueType::kFloat32;
  f.length = 32;
  f.start_bit = 8;
  f.factor = 2.0;
  const float x = -1234.5f;
  insert_raw(f, std::bit_cast<std::uint32_t>(x), d);
  EXPECT_EQ(decode_physical(f, d), static_cast<double>(x) * 2.0);

  Signal g;
  g.value_type = ValueType::kFloat64;
  g.order = ByteOrder::kBigEndian;
  g.length = 64;
  g.start_bit = 7 + 64;  // MSB of byte 8
  const double y = 6.02214076e23;
  insert_raw(g, std::bit_cast<std::uint64_t>(y), d);
  EXPECT_EQ(decode_physical(g, d), y);
}

}  // namespace
}  // namespace resolver::dbc
