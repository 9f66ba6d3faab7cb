// CRC-8 SAE J1850 and the E2E-style counter states.
#include <gtest/gtest.h>

#include <array>
#include <string_view>

#include "daemon/decode/counter_check.h"
#include "daemon/decode/crc8_j1850.h"

namespace resolver {
namespace {

TEST(Crc8J1850, CheckValue) {
  // AUTOSAR SWS CRC library: CRC-8 SAE J1850 check value for "123456789" is 0x4B.
  constexpr std::string_view kCheck = "123456789";
  std::array<std::uint8_t, 9> bytes{};
  for (std::size_t i = 0; i < kCheck.size(); ++i) bytes[i] = static_cast<std::uint8_t>(kCheck[i]);
  EXPECT_EQ(crc8_j1850(bytes), 0x4B);
}

TEST(Crc8J1850, AutosarTableValues) {
  // Further AUTOSAR reference vectors for CRC-8 SAE J1850.
  const std::array<std::uint8_t, 4> zeros{0x00, 0x00, 0x00, 0x00};
  EXPECT_EQ(crc8_j1850(zeros), 0x59);
  const std::array<std::uint8_t, 3> v2{0xF2, 0x01, 0x83};
  EXPECT_EQ(crc8_j1850(v2), 0x37);
  const std::array<std::uint8_t, 4> ff{0xFF, 0xFF, 0xFF, 0xFF};
  EXPECT_EQ(crc8_j1850(ff), 0x74);
}

TEST(Crc8J1850, BenchFrameCrcCoversIdLowByte) {
  std::array<std::uint8_t, 8> data{1, 2, 3, 4, 5, 6, 7, 0};
  const auto a = bench_frame_crc(data.data(), 0x100);
  const auto b = bench_frame_crc(data.data(), 0x101);
  EXPECT_NE(a, b);
  std::array<std::uint8_t, 8> with_id{1, 2, 3, 4, 5, 6, 7, 0x00};
  EXPECT_EQ(a, crc8_j1850(std::span<const std::uint8_t>(with_id.data(), 8)));
}

TEST(CounterCheck, States) {
  CounterCheck c(3);
  EXPECT_EQ(c.check(10), CounterStatus::kInitial);
  EXPECT_EQ(c.check(11), CounterStatus::kOk);
  EXPECT_EQ(c.check(11), CounterStatus::kRepeated);
  EXPECT_EQ(c.check(13), CounterStatus::kSomeLost);
  EXPECT_EQ(c.lost(), 1);
  EXPECT_EQ(c.check(16), CounterStatus::kSomeLost);
  EXPECT_EQ(c.lost(), 2);
  EXPECT_EQ(c.check(30), CounterStatus::kWrongSequence);
  EXPECT_EQ(c.check(31), CounterStatus::kOk) << "resynchronised on the wrong-sequence frame";
}

TEST(CounterCheck, WrapsAt256) {
  CounterCheck c(3);
  c.check(254);
  EXPECT_EQ(c.check(255), CounterStatus::kOk);
  EXPECT_EQ(c.check(0), CounterStatus::kOk);
  EXPECT_EQ(c.check(2), CounterStatus::kSomeLost);
}

}  // namespace
}  // namespace resolver
