#include "daemon/dbc/dbc_codec.h"

#include <array>

namespace resolver::dbc {

namespace {

// A signal of up to 64 bits at any bit offset touches at most 9 bytes; a
// 128-bit integer holds that window without splitting the shift in two.
__extension__ typedef unsigned __int128 Uint128;

constexpr std::size_t kWindowBytes = 9;

struct Window {
  std::uint64_t first_byte = 0;
  std::array<std::uint8_t, kWindowBytes> bytes{};  // zero where beyond the payload
};

// The window's bytes as one integer: byte 0 least significant (Intel) or most
// significant (Motorola), and the right shift that brings the signal's LSB to bit 0.
struct Packed {
  Uint128 value = 0;
  unsigned shift = 0;
};

Packed pack(const Window& w, const Signal& s, const detail::Span& sp) {
  Packed p;
  if (s.order == ByteOrder::kBigEndian) {
    for (std::size_t i = 0; i < kWindowBytes; ++i) p.value = (p.value << 8U) | w.bytes[i];
    // Linear bit L of the window sits at integer bit (8*9 - 1) - L.
    p.shift = static_cast<unsigned>(8U * kWindowBytes - 1U - (sp.last_lin - 8U * w.first_byte));
  } else {
    for (std::size_t i = kWindowBytes; i-- > 0;) p.value = (p.value << 8U) | w.bytes[i];
    p.shift = static_cast<unsigned>(sp.first_lin - 8U * w.first_byte);
  }
  return p;
}

std::uint32_t clamped_length(const Signal& s) {
  return s.length < detail::kMaxSignalBits ? s.length : detail::kMaxSignalBits;
}

}  // namespace

namespace detail {

std::uint64_t extract_raw_slow(const Signal& s, std::uint32_t length, std::span<const std::uint8_t> data) {
  const Span sp = linear_span(s, length);
  Window w;
  w.first_byte = sp.first_lin >> 3U;
  if (w.first_byte >= data.size()) return 0;
  for (std::size_t i = 0; i < kWindowBytes && w.first_byte + i < data.size(); ++i) {
    w.bytes[i] = data[w.first_byte + i];
  }
  const Packed p = pack(w, s, sp);
  return static_cast<std::uint64_t>(p.value >> p.shift) & low_mask(length);
}

}  // namespace detail

bool signal_present(const Message& m, const Signal& s, std::span<const std::uint8_t> data) {
  if (!s.multiplexed_by.has_value()) return true;
  const Signal* mux = m.multiplexor();
  if (mux == nullptr) return false;
  return extract_raw(*mux, data) == *s.multiplexed_by;
}

void insert_raw(const Signal& s, std::uint64_t raw, std::span<std::uint8_t> data) {
  const std::uint32_t length = clamped_length(s);
  if (length == 0) return;
  const detail::Span sp = detail::linear_span(s, length);
  Window w;
  w.first_byte = sp.first_lin >> 3U;
  if (w.first_byte >= data.size()) return;
  const std::size_t avail =
      data.size() - w.first_byte < kWindowBytes ? static_cast<std::size_t>(data.size() - w.first_byte) : kWindowBytes;
  for (std::size_t i = 0; i < avail; ++i) w.bytes[i] = data[w.first_byte + i];

  Packed p = pack(w, s, sp);
  const Uint128 field = static_cast<Uint128>(detail::low_mask(length)) << p.shift;
  p.value = (p.value & ~field) | ((static_cast<Uint128>(raw & detail::low_mask(length)) << p.shift) & field);

  // Unpack in the same byte order and write back only bytes inside the payload.
  for (std::size_t i = 0; i < kWindowBytes; ++i) {
    const std::size_t pos = s.order == ByteOrder::kBigEndian ? kWindowBytes - 1U - i : i;
    w.bytes[pos] = static_cast<std::uint8_t>(p.value >> (8U * i));
  }
  for (std::size_t i = 0; i < avail; ++i) data[w.first_byte + i] = w.bytes[i];
}

}  // namespace resolver::dbc
