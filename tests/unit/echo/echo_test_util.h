// Shared helpers for the echo tests.
#pragma once

#include <cstdint>
#include <vector>

namespace echo_test_support {

/// Encodes an lcm-gen message (fingerprint included) with lcm-gen's own encode().
template <typename T>
std::vector<std::uint8_t> encode(const T& msg) {
  std::vector<std::uint8_t> buf(static_cast<std::size_t>(msg.getEncodedSize()));
  const int n = msg.encode(buf.data(), 0, static_cast<int>(buf.size()));
  buf.resize(n < 0 ? 0 : static_cast<std::size_t>(n));
  return buf;
}

}  // namespace echo_test_support
