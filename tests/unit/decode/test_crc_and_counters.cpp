// CRC-8 SAE J1850 (the counters are the joiner's: test_frame_intake.cpp).
#include <gtest/gtest.h>

#include <array>
#include <string_view>

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

}  // namespace
}  // namespace resolver
