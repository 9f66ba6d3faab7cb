// A deliberately naive reference for the DBC bit layout, used only by tests.
//
// It walks the signal one payload bit at a time, exactly as the DBC definition
// reads: Intel (@1) starts at the LSB and steps to the next higher bit number;
// Motorola (@0) starts at the MSB and steps to the next lower bit of the same
// byte, and from bit 0 of a byte to bit 7 of the next byte (the sawtooth).
// It shares no code or arithmetic trick with daemon/dbc/dbc_codec.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "daemon/dbc/dbc_types.h"

namespace resolver::dbc::test {

/// Payload bit numbers (8*byte + bit, bit 0 = LSB) from the signal's LSB to its MSB.
inline std::vector<std::uint64_t> naive_bit_positions(const Signal& s) {
  std::vector<std::uint64_t> msb_first;
  std::uint64_t pos = s.start_bit;
  for (std::uint32_t i = 0; i < s.length; ++i) {
    msb_first.push_back(pos);
    if (s.order == ByteOrder::kLittleEndian) {
      ++pos;
    } else if (pos % 8 == 0) {
      pos += 15;  // bit 0 of byte b -> bit 7 of byte b+1
    } else {
      --pos;
    }
  }
  if (s.order == ByteOrder::kLittleEndian) return msb_first;  // Intel walk already went LSB first
  return {msb_first.rbegin(), msb_first.rend()};
}

inline bool payload_bit(std::span<const std::uint8_t> data, std::uint64_t pos) {
  const std::uint64_t byte = pos / 8;
  if (byte >= data.size()) return false;
  return ((data[byte] >> (pos % 8)) & 1U) != 0;
}

/// Raw value, bit by bit; bits beyond the payload read as 0.
inline std::uint64_t naive_extract(const Signal& s, std::span<const std::uint8_t> data) {
  const std::vector<std::uint64_t> bits = naive_bit_positions(s);
  std::uint64_t raw = 0;
  for (std::size_t i = 0; i < bits.size(); ++i) {
    if (payload_bit(data, bits[i])) raw |= std::uint64_t{1} << i;
  }
  return raw;
}

/// Two's complement of `length` bits, by filling the high bits with the sign bit one at a time.
inline std::int64_t naive_sign_extend(std::uint64_t raw, std::uint32_t length) {
  if (length == 0 || ((raw >> (length - 1)) & 1U) == 0) return static_cast<std::int64_t>(raw);
  for (std::uint32_t i = length; i < 64; ++i) raw |= std::uint64_t{1} << i;
  return static_cast<std::int64_t>(raw);
}

}  // namespace resolver::dbc::test
