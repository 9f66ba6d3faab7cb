// CRC-8 SAE J1850 as used by the bench layout (docs/ARCHITECTURE.md §4): polynomial 0x1D,
// initial value 0xFF, final XOR 0xFF, no reflection. Check value for the
// ASCII bytes "123456789" is 0x4B (AUTOSAR CRC library spec, Crc_CalculateCRC8).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

namespace resolver {

namespace detail {
constexpr std::array<std::uint8_t, 256> make_crc8_j1850_table() {
  std::array<std::uint8_t, 256> table{};
  for (unsigned i = 0; i < 256; ++i) {
    auto crc = static_cast<std::uint8_t>(i);
    for (int bit = 0; bit < 8; ++bit) {
      crc = (crc & 0x80U) != 0 ? static_cast<std::uint8_t>((crc << 1U) ^ 0x1DU)
                               : static_cast<std::uint8_t>(crc << 1U);
    }
    table[i] = crc;
  }
  return table;
}
inline constexpr auto kCrc8J1850Table = make_crc8_j1850_table();
}  // namespace detail

/// Running CRC register; start from kCrc8J1850Init, finish with crc8_j1850_finish.
inline constexpr std::uint8_t kCrc8J1850Init = 0xFF;

[[nodiscard]] constexpr std::uint8_t crc8_j1850_update(std::uint8_t crc, std::uint8_t byte) {
  return detail::kCrc8J1850Table[static_cast<std::uint8_t>(crc ^ byte)];
}
[[nodiscard]] constexpr std::uint8_t crc8_j1850_finish(std::uint8_t crc) {
  return static_cast<std::uint8_t>(crc ^ 0xFFU);
}

/// CRC-8 J1850 of a byte span. Cannot fail.
[[nodiscard]] constexpr std::uint8_t crc8_j1850(std::span<const std::uint8_t> bytes) {
  std::uint8_t crc = kCrc8J1850Init;
  for (std::uint8_t b : bytes) crc = crc8_j1850_update(crc, b);
  return crc8_j1850_finish(crc);
}

/// The bench layout's frame CRC: over data bytes 0..6 followed by the low byte
/// of the CAN ID (docs/ARCHITECTURE.md §4). `data` must hold at least 7 bytes.
[[nodiscard]] constexpr std::uint8_t bench_frame_crc(const std::uint8_t* data, std::uint32_t can_id) {
  std::uint8_t crc = kCrc8J1850Init;
  for (std::size_t i = 0; i < 7; ++i) crc = crc8_j1850_update(crc, data[i]);
  crc = crc8_j1850_update(crc, static_cast<std::uint8_t>(can_id & 0xFFU));
  return crc8_j1850_finish(crc);
}

}  // namespace resolver
