// Reads the ancillary data (control messages) that come with a recvmsg():
// the kernel receive timestamp and the socket's drop counter.
//
// Understood (level SOL_SOCKET):
//   SCM_TIMESTAMPNS   struct timespec        (SO_TIMESTAMPNS, old and 64-bit "_NEW" form)
//   SCM_TIMESTAMP     struct timeval         (SO_TIMESTAMP, old and "_NEW" form)
//   SCM_TIMESTAMPING  3 x timespec           (SO_TIMESTAMPING: [0] software, [2] raw hardware)
//   SO_RXQ_OVFL       uint32 cumulative count of frames the socket dropped
// When several timestamps arrive, the raw hardware one wins, then nanosecond
// software, then microsecond software. Everything else is ignored.
#pragma once

#include <sys/socket.h>

#include <cstdint>
#include <optional>

namespace resolver {

enum class TimestampKind { kNone, kSoftwareMicro, kSoftwareNano, kHardware };

struct ReceiveMetadata {
  /// [us] since the epoch (CLOCK_REALTIME for software stamps; the adapter's
  /// clock for hardware stamps). Empty when no usable timestamp came.
  std::optional<std::int64_t> timestamp_us;
  /// The same stamp in [ns] (microsecond stamps x 1000): orders frames of
  /// two sockets that arrived within one microsecond (split_wake_source.h).
  std::optional<std::int64_t> timestamp_ns;
  TimestampKind timestamp_kind = TimestampKind::kNone;
  /// Cumulative frames dropped by this socket since it was created (wraps at
  /// 2^32). The kernel omits the cmsg while the count is still zero.
  std::optional<std::uint32_t> drop_counter;
};

/// Frames dropped between two SO_RXQ_OVFL readings of the same socket; the
/// unsigned difference stays right across the counter's wrap at 2^32.
[[nodiscard]] constexpr std::uint32_t drops_since(std::uint32_t previous, std::uint32_t current) {
  return current - previous;
}

/// Parses msg.msg_control / msg_controllen as filled in by recvmsg().
/// Cannot fail: truncated or unknown cmsgs are skipped.
[[nodiscard]] ReceiveMetadata parse_receive_cmsgs(const msghdr& msg);

}  // namespace resolver
