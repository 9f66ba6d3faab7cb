// proto/resolver_bench.dbc must describe exactly what daemon/decode/bench_layout.h
// encodes (docs/ARCHITECTURE.md §4): the two are independent descriptions of one layout.
#include <gtest/gtest.h>

#include <limits>
#include <random>
#include <span>

#include "daemon/core/angles.h"
#include "daemon/dbc/dbc_codec.h"
#include "daemon/dbc/dbc_parser.h"
#include "daemon/decode/bench_layout.h"

namespace resolver::dbc {
namespace {

constexpr const char* kBenchDbc = RESOLVER_SOURCE_DIR "/proto/resolver_bench.dbc";

class BenchDbc : public ::testing::Test {
 protected:
  void SetUp() override {
    db_ = load_dbc_file(kBenchDbc);  // throws (a failed test) naming the file and line
  }

  const Message& message(std::uint32_t id) {
    const Message* m = db_.find_message(id, false);
    EXPECT_NE(m, nullptr) << "no message 0x" << std::hex << id;
    return m != nullptr ? *m : empty_;
  }
  static const Signal& signal(const Message& m, std::string_view name) {
    static const Signal missing;
    const Signal* s = m.find_signal(name);
    EXPECT_NE(s, nullptr) << m.name << " has no signal " << name;
    return s != nullptr ? *s : missing;
  }
  static std::span<const std::uint8_t> payload(const CanFrame& f) { return {f.data.data(), f.len}; }

  Database db_;
  Message empty_;
};

TEST_F(BenchDbc, MessagesMatchTheLayoutConstants) {
  ASSERT_TRUE(db_.warnings.empty()) << db_.warnings.front();
  ASSERT_EQ(db_.messages.size(), 4U);
  const std::pair<std::uint32_t, const char*> expected[] = {{bench::kIdResolverSample, "RESOLVER_SAMPLE"},
                                                            {bench::kIdPhaseCurrents, "PHASE_CURRENTS"},
                                                            {bench::kIdReferenceAngle, "REFERENCE_ANGLE"},
                                                            {bench::kIdBenchInfo, "BENCH_INFO"}};
  for (const auto& [id, name] : expected) {
    const Message& m = message(id);
    EXPECT_EQ(m.name, name);
    EXPECT_EQ(m.dlc, bench::kFrameLen);
    EXPECT_FALSE(m.extended);
    EXPECT_FALSE(m.comment.empty()) << name;
    for (const Signal& s : m.signals) {
      EXPECT_EQ(s.order, ByteOrder::kLittleEndian) << name << "." << s.name;
      EXPECT_FALSE(s.comment.empty()) << name << "." << s.name << " needs a CM_";
    }
  }
  // The scale factors are the layout's own numbers, to the last bit.
  EXPECT_EQ(signal(message(bench::kIdResolverSample), "rd_angle").factor, kTwoPi / bench::kRdAngleCounts);
  EXPECT_EQ(signal(message(bench::kIdReferenceAngle), "ref_angle").factor, kTwoPi / bench::kRefAngleCounts);
  EXPECT_EQ(signal(message(bench::kIdPhaseCurrents), "i_a").factor, bench::kCurrentAmpsPerBit);
  EXPECT_EQ(signal(message(bench::kIdResolverSample), "sin").unit, "counts");
  EXPECT_EQ(signal(message(bench::kIdPhaseCurrents), "i_c").unit, "A");
  EXPECT_EQ(signal(message(bench::kIdBenchInfo), "sample_rate_hz").unit, "Hz");
  EXPECT_EQ(signal(message(bench::kIdBenchInfo), "layout_version").value_table.count(bench::kLayoutVersion), 1U);
}

// Random values plus the extremes of each field's type.
template <typename T>
T pick(std::mt19937_64& rng, int i) {
  if (i == 0) return std::numeric_limits<T>::min();
  if (i == 1) return std::numeric_limits<T>::max();
  if (i == 2) return T{0};
  return static_cast<T>(rng());
}

constexpr int kFrames = 3000;

TEST_F(BenchDbc, DecodesResolverSampleAsEncoded) {
  const Message& m = message(bench::kIdResolverSample);
  std::mt19937_64 rng(11);
  for (int i = 0; i < kFrames; ++i) {
    const auto counter = pick<std::uint8_t>(rng, i);
    const auto sn = pick<std::int16_t>(rng, i);
    const auto cs = pick<std::int16_t>(rng, i + 1);  // opposite extreme to sin
    const auto rd = pick<std::uint16_t>(rng, i);
    const CanFrame f = bench::encode_resolver_sample(0, counter, sn, cs, rd);
    const auto d = payload(f);
    EXPECT_EQ(extract_raw(signal(m, "counter"), d), counter);
    EXPECT_EQ(extract_signed(signal(m, "sin"), d), sn);
    EXPECT_EQ(extract_signed(signal(m, "cos"), d), cs);
    EXPECT_EQ(decode_physical(signal(m, "sin"), d), static_cast<double>(sn));
    EXPECT_EQ(extract_raw(signal(m, "rd_angle"), d), rd);
    // raw * (2pi/65536) with the factor bit-identical (checked above): exact.
    EXPECT_EQ(decode_physical(signal(m, "rd_angle"), d), static_cast<double>(rd) * (kTwoPi / bench::kRdAngleCounts));
    EXPECT_EQ(extract_raw(signal(m, "crc"), d), f.data[7]);
  }
}

TEST_F(BenchDbc, DecodesPhaseCurrentsAsEncoded) {
  const Message& m = message(bench::kIdPhaseCurrents);
  std::mt19937_64 rng(12);
  for (int i = 0; i < kFrames; ++i) {
    const auto counter = pick<std::uint8_t>(rng, i);
    const auto a = pick<std::int16_t>(rng, i);
    const auto b = pick<std::int16_t>(rng, i + 1);
    const auto c = pick<std::int16_t>(rng, i + 2);
    const CanFrame f = bench::encode_phase_currents(0, counter, a, b, c);
    const auto d = payload(f);
    EXPECT_EQ(extract_raw(signal(m, "counter"), d), counter);
    EXPECT_EQ(extract_signed(signal(m, "i_a"), d), a);
    EXPECT_EQ(extract_signed(signal(m, "i_b"), d), b);
    EXPECT_EQ(extract_signed(signal(m, "i_c"), d), c);
    EXPECT_EQ(decode_physical(signal(m, "i_b"), d), static_cast<double>(b) * bench::kCurrentAmpsPerBit);
    EXPECT_EQ(extract_raw(signal(m, "crc"), d), f.data[7]);
  }
}

TEST_F(BenchDbc, DecodesReferenceAngleAsEncoded) {
  const Message& m = message(bench::kIdReferenceAngle);
  std::mt19937_64 rng(13);
  for (int i = 0; i < kFrames; ++i) {
    const auto counter = pick<std::uint8_t>(rng, i);
    const auto ref = pick<std::uint32_t>(rng, i);
    const CanFrame f = bench::encode_reference_angle(0, counter, ref);
    const auto d = payload(f);
    EXPECT_EQ(extract_raw(signal(m, "counter"), d), counter);
    EXPECT_EQ(extract_raw(signal(m, "ref_angle"), d), ref);
    EXPECT_EQ(decode_physical(signal(m, "ref_angle"), d), static_cast<double>(ref) * (kTwoPi / bench::kRefAngleCounts));
    EXPECT_EQ(extract_raw(signal(m, "reserved"), d), 0U);
    EXPECT_EQ(extract_raw(signal(m, "crc"), d), f.data[7]);
  }
}

TEST_F(BenchDbc, DecodesBenchInfoAsEncoded) {
  const Message& m = message(bench::kIdBenchInfo);
  std::mt19937_64 rng(14);
  for (int i = 0; i < kFrames; ++i) {
    const auto p_r = pick<std::uint8_t>(rng, i);
    const auto p = pick<std::uint8_t>(rng, i + 1);
    const auto bits = pick<std::uint8_t>(rng, i + 2);
    const auto rate = pick<std::uint16_t>(rng, i);
    const CanFrame f = bench::encode_bench_info(0, p_r, p, bits, rate);
    const auto d = payload(f);
    EXPECT_EQ(extract_raw(signal(m, "layout_version"), d), bench::kLayoutVersion);
    EXPECT_EQ(extract_raw(signal(m, "p_r"), d), p_r);
    EXPECT_EQ(extract_raw(signal(m, "p"), d), p);
    EXPECT_EQ(extract_raw(signal(m, "rd_bits"), d), bits);
    EXPECT_EQ(decode_physical(signal(m, "sample_rate_hz"), d), static_cast<double>(rate));
    EXPECT_EQ(extract_raw(signal(m, "reserved"), d), 0U);
    EXPECT_EQ(extract_raw(signal(m, "crc"), d), f.data[7]);
  }
}

// Every payload bit belongs to exactly one signal: the DBC leaves no gap and no overlap.
TEST_F(BenchDbc, SignalsTileTheEightBytes) {
  for (const Message& m : db_.messages) {
    std::array<std::uint8_t, 8> owners{};
    for (const Signal& s : m.signals) {
      std::array<std::uint8_t, 8> d{};
      insert_raw(s, ~std::uint64_t{0}, d);
      for (std::size_t b = 0; b < d.size(); ++b) {
        EXPECT_EQ(owners[b] & d[b], 0) << m.name << "." << s.name << " overlaps byte " << b;
        owners[b] = static_cast<std::uint8_t>(owners[b] | d[b]);
      }
    }
    for (std::size_t b = 0; b < owners.size(); ++b) EXPECT_EQ(owners[b], 0xFF) << m.name << " byte " << b;
  }
}

}  // namespace
}  // namespace resolver::dbc
