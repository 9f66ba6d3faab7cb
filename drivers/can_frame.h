// The one CAN frame type every source and sink in the project speaks.
//
// A CanFrame is a plain value (no heap): classic CAN (0..8 bytes), CAN FD
// (0..64 bytes), remote (RTR) and error frames, with the timestamp the frame
// was received at (from a candump log or the kernel's SO_TIMESTAMP).
#pragma once

#include <array>
#include <cstdint>
#include <string_view>

namespace resolver {

struct CanFrame {
  static constexpr std::size_t kMaxClassicLen = 8;
  static constexpr std::size_t kMaxFdLen = 64;
  static constexpr std::size_t kMaxIfaceLen = 16;  // IFNAMSIZ incl. NUL

  /// Arbitration ID without flag bits: 11 bits standard, 29 bits extended.
  /// For error frames: the CAN_ERR_* class bits (linux/can/error.h).
  std::uint32_t id = 0;
  bool extended = false;
  bool rtr = false;     ///< remote transmission request (classic only)
  bool error = false;   ///< error frame (data holds the error details)
  bool fd = false;      ///< CAN FD frame
  std::uint8_t fd_flags = 0;  ///< CANFD_BRS = 0x01, CANFD_ESI = 0x02
  std::uint8_t len = 0;       ///< payload length [bytes]
  std::array<std::uint8_t, kMaxFdLen> data{};
  /// [us] receive time: seconds since the epoch (or log start) * 1e6.
  std::int64_t timestamp_us = 0;
  /// Interface name as logged / received ("can0", "vcan0"); NUL-terminated.
  std::array<char, kMaxIfaceLen> iface{};

  [[nodiscard]] std::string_view iface_name() const {
    std::size_t n = 0;
    while (n < iface.size() && iface[n] != '\0') ++n;
    return {iface.data(), n};
  }
  /// Stores `name`, truncated to 15 characters.
  void set_iface(std::string_view name) {
    iface.fill('\0');
    const std::size_t n = name.size() < kMaxIfaceLen - 1 ? name.size() : kMaxIfaceLen - 1;
    for (std::size_t i = 0; i < n; ++i) iface[i] = name[i];
  }
};

}  // namespace resolver
