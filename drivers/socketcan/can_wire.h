// Conversion between CanFrame and the byte images CAN_RAW reads and writes.
//
// A CAN_RAW socket hands over one frame per read: a 16-byte `struct can_frame`
// (CAN_MTU) for classic CAN or a 72-byte `struct canfd_frame` (CANFD_MTU) for
// CAN FD; the read size is what tells them apart (kernel
// Documentation/networking/can.rst, "RAW socket option CAN_RAW_FD_FRAMES").
// The first 32-bit word (host byte order) carries the ID plus the flag bits
// EFF (bit 31, extended ID), RTR (bit 30) and ERR (bit 29, error frame).
//
// Pure functions: no sockets, no clocks. They neither read nor write
// CanFrame::timestamp_us or CanFrame::iface; the socket layer fills those.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

#include "drivers/can_frame.h"

namespace resolver {

inline constexpr std::size_t kCanMtu = 16;    ///< sizeof(struct can_frame) [bytes]
inline constexpr std::size_t kCanFdMtu = 72;  ///< sizeof(struct canfd_frame) [bytes]

/// Room for either image; a classic frame uses the first kCanMtu bytes.
using CanWireImage = std::array<std::uint8_t, kCanFdMtu>;

enum class WireDecodeStatus {
  kOk,
  kBadSize,    ///< image is neither kCanMtu nor kCanFdMtu bytes (short or oversized read)
  kBadLength,  ///< length byte exceeds 8 (classic) or 64 (FD)
};

[[nodiscard]] std::string_view to_string(WireDecodeStatus status);

/// Decodes one CAN_RAW read. Cannot throw. On kOk every field except
/// timestamp_us and iface is overwritten (data beyond `len` is zeroed);
/// on failure `frame` is left unchanged.
/// Error frames (ERR flag) come out with error = true and id = the CAN_ERR_*
/// class bits; FD flags keep only BRS and ESI (the kernel also sets FDF).
[[nodiscard]] WireDecodeStatus decode_wire_frame(std::span<const std::uint8_t> image,
                                                 CanFrame& frame);

/// Encodes `frame` into `image`; returns the number of bytes to write
/// (kCanMtu or kCanFdMtu). Throws std::invalid_argument, naming the field,
/// for a frame the kernel would reject or that cannot be represented:
/// standard ID > 0x7FF, extended ID > 0x1FFFFFFF, len > 8 (classic) or
/// > 64 (FD), RTR on an FD frame, fd_flags other than BRS/ESI.
std::size_t encode_wire_frame(const CanFrame& frame, CanWireImage& image);

}  // namespace resolver
