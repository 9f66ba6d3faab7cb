// append_candump_line() and check_loggable(): format into a stack buffer with
// hand-rolled digits (no printf, no allocation beyond `out` growing).
#include <array>
#include <cstdint>

#include <fmt/format.h>

#include "drivers/candump/candump_line.h"

namespace resolver {
namespace {

constexpr std::uint32_t kCanErrFlag = 0x20000000U;  // CAN_ERR_FLAG (linux/can.h)
constexpr std::uint32_t kCanEffMask = 0x1FFFFFFFU;  // CAN_EFF_MASK
constexpr std::uint32_t kCanSffMask = 0x000007FFU;  // CAN_SFF_MASK
constexpr std::uint8_t kFdFlagsKnown = 0x03U;       // BRS | ESI
constexpr int kSecondsWidth = 10;                   // candump's "%010ld"
constexpr char kHexDigits[] = "0123456789ABCDEF";

// "(" + 19 digits + "." + 6 + ") " + 15 + " " + 8 + "##" + 1 + 128 + "\n" = 184.
constexpr std::size_t kMaxLineBytes = 256;

bool is_fd_length(std::size_t n) {
  return n <= 8 || n == 12 || n == 16 || n == 20 || n == 24 || n == 32 || n == 48 || n == 64;
}

bool is_iface_char(char c) {
  const auto u = static_cast<unsigned char>(c);
  return u > 0x20 && u < 0x7F;  // no blanks or control bytes: they would split the field
}

char* put_hex(char* p, std::uint32_t value, int digits) {
  for (int shift = 4 * (digits - 1); shift >= 0; shift -= 4) {
    *p++ = kHexDigits[(value >> static_cast<unsigned>(shift)) & 0xFU];
  }
  return p;
}

char* put_decimal(char* p, std::uint64_t value, int min_width) {
  std::array<char, 20> digits{};  // 2^64 has 20 decimal digits
  int n = 0;
  do {
    digits[static_cast<std::size_t>(n++)] = static_cast<char>('0' + value % 10U);
    value /= 10U;
  } while (value != 0U);
  while (n < min_width) digits[static_cast<std::size_t>(n++)] = '0';
  while (n > 0) *p++ = digits[static_cast<std::size_t>(--n)];
  return p;
}

}  // namespace

void check_loggable(const CanFrame& frame, const Where& where) {
  const auto refuse = [&](const std::string& why) {
    throw InputError(Fault::kUsage, "cannot log this frame: " + why, where);
  };
  if (frame.timestamp_us < 0) {
    refuse(fmt::format("timestamp {} us is negative; candump logs hold times since the epoch",
                       frame.timestamp_us));
  }
  const std::string_view iface = frame.iface_name();
  if (iface.empty()) refuse("interface name is empty; set it with set_iface(\"can0\")");
  for (const char c : iface) {
    if (!is_iface_char(c)) {
      refuse(fmt::format("interface name '{}' contains a blank or control character", iface));
    }
  }
  if (frame.error) {
    if (frame.fd || frame.rtr) refuse("error frames cannot be CAN FD or remote frames");
    if (frame.id > kCanEffMask) {
      refuse(fmt::format("error class bits 0x{:X} exceed 29 bits", frame.id));
    }
  } else if (frame.extended ? frame.id > kCanEffMask : frame.id > kCanSffMask) {
    refuse(fmt::format("{} CAN ID 0x{:X} exceeds 0x{:X}", frame.extended ? "29-bit" : "11-bit",
                       frame.id, frame.extended ? kCanEffMask : kCanSffMask));
  }
  if (frame.fd) {
    if (frame.rtr) refuse("CAN FD has no remote frames");
    if ((frame.fd_flags & ~kFdFlagsKnown) != 0U) {
      refuse(fmt::format("CAN FD flags 0x{:X} have bits other than BRS=1, ESI=2", frame.fd_flags));
    }
    if (!is_fd_length(frame.len)) {
      refuse(fmt::format("CAN FD length {} is not one of 0..8, 12, 16, 20, 24, 32, 48, 64",
                         frame.len));
    }
  } else if (frame.len > CanFrame::kMaxClassicLen) {
    refuse(fmt::format("classic CAN length {} exceeds 8 bytes", frame.len));
  } else if (frame.fd_flags != 0U) {
    // candump has nowhere to put them on a classic line; they would be lost.
    refuse(fmt::format("CAN FD flags 0x{:X} set on a classic (non-FD) frame", frame.fd_flags));
  }
}

void append_candump_line(const CanFrame& frame, std::string& out) {
  std::array<char, kMaxLineBytes> buffer{};
  char* p = buffer.data();

  const auto micros = static_cast<std::uint64_t>(frame.timestamp_us < 0 ? 0 : frame.timestamp_us);
  *p++ = '(';
  p = put_decimal(p, micros / 1'000'000U, kSecondsWidth);
  *p++ = '.';
  p = put_decimal(p, micros % 1'000'000U, 6);
  *p++ = ')';
  *p++ = ' ';

  const std::string_view iface = frame.iface_name();
  if (iface.empty()) {
    *p++ = '-';  // keeps the line three fields wide; check_loggable() reports it
  } else {
    for (const char c : iface) *p++ = is_iface_char(c) ? c : '_';
  }
  *p++ = ' ';

  if (frame.error) {
    p = put_hex(p, (frame.id & kCanEffMask) | kCanErrFlag, 8);
  } else if (frame.extended) {
    p = put_hex(p, frame.id & kCanEffMask, 8);
  } else {
    p = put_hex(p, frame.id & kCanSffMask, 3);
  }
  *p++ = '#';

  const bool fd = frame.fd && !frame.error;
  if (fd) {
    *p++ = '#';
    *p++ = kHexDigits[frame.fd_flags & kFdFlagsKnown];
  }
  if (frame.rtr && !fd && !frame.error) {
    // candump writes the requested length only when it is not zero ("123#R", "123#R5").
    *p++ = 'R';
    const std::size_t len = frame.len < CanFrame::kMaxClassicLen ? frame.len : CanFrame::kMaxClassicLen;
    if (len != 0) *p++ = static_cast<char>('0' + len);
  } else {
    const std::size_t max_len = fd ? CanFrame::kMaxFdLen : CanFrame::kMaxClassicLen;
    const std::size_t len = frame.len < max_len ? frame.len : max_len;
    for (std::size_t k = 0; k < len; ++k) {
      *p++ = kHexDigits[frame.data[k] >> 4U];
      *p++ = kHexDigits[frame.data[k] & 0xFU];
    }
  }
  *p++ = '\n';
  out.append(buffer.data(), static_cast<std::size_t>(p - buffer.data()));
}

}  // namespace resolver
