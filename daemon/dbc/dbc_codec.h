// Signal codec: raw bits <-> payload bytes, and raw -> physical value.
//
// These functions are on the daemon's hot path (every frame, target >= 2 M
// frames/s), so extraction is inline and, whenever the signal lies inside an
// 8-byte window of the payload, costs one unaligned 64-bit load, a byte swap
// for Motorola, a shift and a mask. Nothing is precomputed in Signal: the
// window arithmetic is a handful of integer ops, and tests and tools may build
// Signals by hand.
//
// None of these functions can fail: bits that lie beyond `data` read as zero
// (and are not written), a length above 64 is treated as 64, a length of 0
// decodes as 0. Bit numbering is described in dbc_types.h.
#pragma once

#include <bit>
#include <cstdint>
#include <cstring>
#include <span>

#include "daemon/dbc/dbc_types.h"

namespace resolver::dbc {

namespace detail {

inline constexpr std::uint32_t kMaxSignalBits = 64;

[[nodiscard]] inline std::uint64_t low_mask(std::uint32_t length) {
  if (length >= kMaxSignalBits) return ~std::uint64_t{0};
  return (std::uint64_t{1} << length) - 1U;
}

/// 8 bytes at data[at..at+7] (caller checked they exist) as a little/big-endian word.
[[nodiscard]] inline std::uint64_t load64(const std::uint8_t* at, bool big_endian) {
  std::uint64_t v = 0;
  std::memcpy(&v, at, sizeof v);
  const bool swap = big_endian == (std::endian::native == std::endian::little);
  return swap ? __builtin_bswap64(v) : v;
}

/// Position of the signal in a numbering where it is one contiguous run:
/// Intel uses L = 8*byte + k (the DBC number itself, LSB of each byte first);
/// Motorola uses L = 8*byte + (7 - k) (MSB of each byte first), which turns the
/// sawtooth into a straight line. Either way the signal is L = first_lin ..
/// first_lin + length - 1, all within bytes first_lin/8 .. last_lin/8.
struct Span {
  std::uint64_t first_lin = 0;  ///< Intel: the LSB; Motorola: the MSB
  std::uint64_t last_lin = 0;   ///< Intel: the MSB; Motorola: the LSB
};

[[nodiscard]] inline Span linear_span(const Signal& s, std::uint32_t length) {
  const std::uint64_t first = s.order == ByteOrder::kBigEndian ? (std::uint64_t{s.start_bit} ^ 7U) : s.start_bit;
  return {first, first + length - 1U};
}

/// Slow path: the signal straddles 9 bytes or runs past the end of `data`.
std::uint64_t extract_raw_slow(const Signal& s, std::uint32_t length, std::span<const std::uint8_t> data);

}  // namespace detail

/// Raw bits of `s` in `data`, unsigned, right-aligned. Bits beyond `data` are zero.
[[nodiscard]] inline std::uint64_t extract_raw(const Signal& s, std::span<const std::uint8_t> data) {
  const std::uint32_t length = s.length < detail::kMaxSignalBits ? s.length : detail::kMaxSignalBits;
  if (length == 0) return 0;
  const detail::Span sp = detail::linear_span(s, length);
  const std::uint64_t first_byte = sp.first_lin >> 3U;
  const std::uint64_t last_byte = sp.last_lin >> 3U;
  const std::uint64_t size = data.size();
  if (size >= 8 && last_byte < size) {
    // Any 8-byte window [w, w+7] that contains the signal will do; prefer the
    // signal's first byte, slide back so the window stays inside the payload.
    const std::uint64_t w = first_byte < size - 8 ? first_byte : size - 8;
    if (last_byte <= w + 7) {
      const bool big = s.order == ByteOrder::kBigEndian;
      const std::uint64_t word = detail::load64(data.data() + w, big);
      const std::uint64_t rel = big ? (63U - (sp.last_lin - 8U * w)) : (sp.first_lin - 8U * w);
      return (word >> rel) & detail::low_mask(length);
    }
  }
  return detail::extract_raw_slow(s, length, data);
}

/// Raw value, sign-extended from `length` bits when `s.is_signed`
/// (an unsigned 64-bit signal above INT64_MAX wraps to negative).
[[nodiscard]] inline std::int64_t extract_signed(const Signal& s, std::span<const std::uint8_t> data) {
  const std::uint64_t raw = extract_raw(s, data);
  if (!s.is_signed || s.length == 0 || s.length >= detail::kMaxSignalBits) return static_cast<std::int64_t>(raw);
  const std::uint64_t sign = std::uint64_t{1} << (s.length - 1U);
  // (raw ^ sign) - sign maps [0, 2^n) onto [-2^(n-1), 2^(n-1)) without branches.
  return static_cast<std::int64_t>(raw ^ sign) - static_cast<std::int64_t>(sign);
}

/// Physical value raw * factor + offset (raw as IEEE float for SIG_VALTYPE_ signals).
[[nodiscard]] inline double decode_physical(const Signal& s, std::span<const std::uint8_t> data) {
  double value = 0.0;
  switch (s.value_type) {
    case ValueType::kFloat32:
      value = static_cast<double>(std::bit_cast<float>(static_cast<std::uint32_t>(extract_raw(s, data))));
      break;
    case ValueType::kFloat64:
      value = std::bit_cast<double>(extract_raw(s, data));
      break;
    case ValueType::kInteger:
      value = s.is_signed ? static_cast<double>(extract_signed(s, data)) : static_cast<double>(extract_raw(s, data));
      break;
  }
  return value * s.factor + s.offset;
}

/// False when `s` is multiplexed (m<value>) and the message's multiplexor
/// currently carries another value, or the message has no multiplexor.
[[nodiscard]] bool signal_present(const Message& m, const Signal& s, std::span<const std::uint8_t> data);

/// Writes the low `s.length` bits of `raw` into `data` at the signal's position;
/// every other bit of `data` is left as it was. Bits beyond `data` are dropped.
void insert_raw(const Signal& s, std::uint64_t raw, std::span<std::uint8_t> data);

}  // namespace resolver::dbc
