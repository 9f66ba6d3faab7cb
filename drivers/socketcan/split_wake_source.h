// SplitWakeSource: one CAN interface read through two CAN_RAW sockets, so the
// reader wakes up only for the frames that need an answer at once.
//
// Why: at a saturated bus every frame wakes a reader that waits on one socket,
// and each wake-up costs the scheduler several microseconds (about 5 us on a
// KVM guest: docs/PERFORMANCE.md, "Live latency"). A sample of the default
// bench layout spans three frames, and only the one that completes it makes
// resolverd publish; the other two can wait in the kernel until then.
//
//   waking socket: the frames whose IDs are in `wake` (plus error frames);
//                  read() blocks on it, up to read_timeout
//   quiet socket:  every other frame (inverted, joined filters); never waited
//                  on, drained without blocking when the waking socket returns
//
// read() hands frames out in arrival order (kernel timestamps in ns, as one
// socket would): when a waking frame arrives, the quiet frames stamped at or before
// it come first, then the waking frame; quiet frames stamped after it wait for
// the next waking frame, or for read_timeout when none comes. Nothing is
// dropped: a quiet frame waits at most read_timeout, and drained frames are
// handed out before a kNetworkDown/kDeviceGone is reported. Kernel drop and
// other counts are the sums of both sockets.
//
// With an empty `wake` list there is one socket and read() is exactly
// SocketCanSource::read(): every frame wakes the reader.
//
// Threading: as SocketCanSource (one thread calls read()).
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <optional>
#include <vector>

#include "drivers/can_frame.h"
#include "drivers/socketcan/can_filter.h"
#include "drivers/socketcan/socketcan_source.h"

namespace resolver {

class SplitWakeSource {
 public:
  /// Opens the interface in `options.iface` (whose filters must be empty:
  /// this class sets them). `wake`: the IDs that wake the reader; empty = all.
  /// Throws SocketCanError as SocketCanSource::open, or with EINVAL when
  /// `options.filters` is not empty.
  static SplitWakeSource open(const SocketCanOptions& options, const std::vector<CanIdFilter>& wake);

  /// Takes two open sockets: `waking` is waited on, `quiet` only drained
  /// (tests and the host benchmark, which route frames to a socket pair each).
  SplitWakeSource(SocketCanSource waking, std::optional<SocketCanSource> quiet);

  /// As SocketCanSource::read(). kTimeout only when neither socket had a frame.
  ReadStatus read(CanFrame& frame);

  /// Both sockets' counts added up (timeouts and network_down: the waking
  /// socket's only, as the quiet one is never waited on).
  [[nodiscard]] SocketCanStats stats() const;
  /// Quiet frames read from the kernel and not handed out yet.
  [[nodiscard]] std::size_t queued() const { return quiet_frames_.size(); }
  [[nodiscard]] bool split() const { return quiet_.has_value(); }
  [[nodiscard]] const std::string& iface() const { return waking_.iface(); }
  void set_read_timeout(std::chrono::milliseconds timeout) { waking_.set_read_timeout(timeout); }

 private:
  /// Moves every frame queued in the quiet socket into quiet_frames_. A
  /// truncated read is remembered and reported by the next read().
  void drain_quiet();
  /// Hands out the oldest drained quiet frame.
  ReadStatus pop_quiet(CanFrame& frame);

  SocketCanSource waking_;
  std::optional<SocketCanSource> quiet_;
  /// A frame and its receive stamp at full resolution: at vcan speed two
  /// frames can arrive within one microsecond.
  struct Stamped {
    CanFrame frame;
    std::int64_t stamp_ns = 0;
  };
  std::optional<Stamped> held_;         ///< waking frame waiting for older quiet frames
  std::deque<Stamped> quiet_frames_;    ///< drained, in arrival order
  std::optional<ReadStatus> deferred_;  ///< waking socket's status, after the drained frames
  std::uint64_t truncated_pending_ = 0; ///< quiet kTruncated results not reported yet
};

}  // namespace resolver
