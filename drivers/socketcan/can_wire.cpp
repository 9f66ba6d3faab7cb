#include "drivers/socketcan/can_wire.h"

#include <linux/can.h>
#include <linux/can/error.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <string>

namespace resolver {
namespace {

static_assert(kCanMtu == CAN_MTU, "struct can_frame size changed");
static_assert(kCanFdMtu == CANFD_MTU, "struct canfd_frame size changed");
static_assert(CanFrame::kMaxClassicLen == CAN_MAX_DLEN);
static_assert(CanFrame::kMaxFdLen == CANFD_MAX_DLEN);

// Only these two flags mean something to a receiver; FDF is a kernel marker.
constexpr std::uint8_t kFdFlagsKept = CANFD_BRS | CANFD_ESI;

std::string hex(std::uint32_t value) {
  std::array<char, 16> text{};
  std::snprintf(text.data(), text.size(), "0x%X", value);
  return text.data();
}

void fill_id(std::uint32_t can_id, CanFrame& frame) {
  frame.error = (can_id & CAN_ERR_FLAG) != 0U;
  if (frame.error) {
    frame.id = can_id & CAN_ERR_MASK;
    frame.extended = false;
    frame.rtr = false;
    return;
  }
  frame.extended = (can_id & CAN_EFF_FLAG) != 0U;
  frame.rtr = (can_id & CAN_RTR_FLAG) != 0U;
  frame.id = can_id & (frame.extended ? CAN_EFF_MASK : CAN_SFF_MASK);
}

std::uint32_t make_can_id(const CanFrame& frame) {
  if (frame.error) {
    if ((frame.id & ~CAN_ERR_MASK) != 0U) {
      throw std::invalid_argument("error frame class bits " + hex(frame.id) +
                                  " exceed CAN_ERR_MASK (29 bits)");
    }
    return CAN_ERR_FLAG | frame.id;
  }
  std::uint32_t can_id = 0;
  if (frame.extended) {
    if (frame.id > CAN_EFF_MASK) {
      throw std::invalid_argument("extended CAN ID " + hex(frame.id) +
                                  " exceeds 29 bits (max 0x1FFFFFFF)");
    }
    can_id = frame.id | CAN_EFF_FLAG;
  } else {
    if (frame.id > CAN_SFF_MASK) {
      throw std::invalid_argument("standard CAN ID " + hex(frame.id) +
                                  " exceeds 11 bits (max 0x7FF); set extended = true for 29-bit IDs");
    }
    can_id = frame.id;
  }
  if (frame.rtr) can_id |= CAN_RTR_FLAG;
  return can_id;
}

}  // namespace

std::string_view to_string(WireDecodeStatus status) {
  switch (status) {
    case WireDecodeStatus::kOk: return "ok";
    case WireDecodeStatus::kBadSize: return "read size is neither CAN_MTU (16) nor CANFD_MTU (72)";
    case WireDecodeStatus::kBadLength: return "length byte exceeds the frame type's maximum";
  }
  return "unknown";
}

WireDecodeStatus decode_wire_frame(std::span<const std::uint8_t> image, CanFrame& frame) {
  if (image.size() == kCanMtu) {
    can_frame raw{};
    std::memcpy(&raw, image.data(), sizeof raw);
    if (raw.len > CAN_MAX_DLEN) return WireDecodeStatus::kBadLength;
    fill_id(raw.can_id, frame);
    frame.fd = false;
    frame.fd_flags = 0;
    frame.len = raw.len;
    frame.data.fill(0);
    // A remote frame's len is the requested DLC; it carries no payload.
    if (!frame.rtr) std::copy_n(raw.data, raw.len, frame.data.begin());
    return WireDecodeStatus::kOk;
  }
  if (image.size() == kCanFdMtu) {
    canfd_frame raw{};
    std::memcpy(&raw, image.data(), sizeof raw);
    if (raw.len > CANFD_MAX_DLEN) return WireDecodeStatus::kBadLength;
    fill_id(raw.can_id, frame);
    frame.rtr = false;  // CAN FD has no remote frames
    frame.fd = true;
    frame.fd_flags = static_cast<std::uint8_t>(raw.flags & kFdFlagsKept);
    frame.len = raw.len;
    frame.data.fill(0);
    std::copy_n(raw.data, raw.len, frame.data.begin());
    return WireDecodeStatus::kOk;
  }
  return WireDecodeStatus::kBadSize;
}

std::size_t encode_wire_frame(const CanFrame& frame, CanWireImage& image) {
  const std::uint32_t can_id = make_can_id(frame);
  image.fill(0);
  if (!frame.fd) {
    if (frame.len > CAN_MAX_DLEN) {
      throw std::invalid_argument("classic CAN frame len " + std::to_string(frame.len) +
                                  " exceeds 8 bytes; set fd = true for longer payloads");
    }
    can_frame raw{};
    raw.can_id = can_id;
    raw.len = frame.len;
    if (!frame.rtr) std::copy_n(frame.data.begin(), frame.len, raw.data);
    std::memcpy(image.data(), &raw, sizeof raw);
    return kCanMtu;
  }
  if (frame.rtr) throw std::invalid_argument("CAN FD frames cannot be remote (RTR) frames");
  if (frame.len > CANFD_MAX_DLEN) {
    throw std::invalid_argument("CAN FD frame len " + std::to_string(frame.len) +
                                " exceeds 64 bytes");
  }
  if ((frame.fd_flags & ~kFdFlagsKept) != 0) {
    throw std::invalid_argument("CAN FD flags " + hex(frame.fd_flags) +
                                " contain bits other than BRS (0x01) and ESI (0x02)");
  }
  canfd_frame raw{};
  raw.can_id = can_id;
  raw.len = frame.len;
  raw.flags = frame.fd_flags;
  std::copy_n(frame.data.begin(), frame.len, raw.data);
  std::memcpy(image.data(), &raw, sizeof raw);
  return kCanFdMtu;
}

}  // namespace resolver
