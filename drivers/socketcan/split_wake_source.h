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
//                  on while waking frames come, read without blocking
//
// read() hands frames out in arrival order (kernel timestamps in ns, as one
// socket would): quiet frames stamped at or before a waking frame come before
// it; quiet frames after the last waking frame wait for the next one, or for
// read_timeout, after which they are handed out as they come. Nothing is
// dropped: the frames both sockets had queued when a kNetworkDown or
// kDeviceGone came are handed out before it is reported (frames stamped later
// after it, so a saturated bus cannot hold the status back). Kernel drop and other counts are the sums of both
// sockets. One quiet frame at most is held in user space.
//
// set_wake() changes the split on the live sockets: the waking socket's
// filters are replaced in place (what it has queued stays), the quiet socket
// is opened before / emptied after, and a frame both sockets received in the
// moment of the change (same skb, so the same stamp, ID and data) is handed
// out once.
//
// With no wake IDs there is one socket and read() is SocketCanSource::read():
// every frame wakes the reader.
//
// Threading: as SocketCanSource (one thread calls read()).
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include "drivers/can_frame.h"
#include "drivers/socketcan/can_filter.h"
#include "drivers/socketcan/socketcan_source.h"

namespace resolver {

class SplitWakeSource {
 public:
  /// Opens `options.iface` (whose filters must be empty: this class sets
  /// them). `wake`: the IDs that wake the reader; empty = every frame.
  /// Throws SocketCanError as SocketCanSource::open, or with EINVAL when
  /// `options.filters` is not empty.
  static SplitWakeSource open(const SocketCanOptions& options, const std::vector<CanIdFilter>& wake);

  /// Takes two open sockets: `waking` is waited on, `quiet` only read when
  /// it has frames (tests and the host benchmark, which route frames to a
  /// socket pair each). set_wake() needs a source from open().
  SplitWakeSource(SocketCanSource waking, std::optional<SocketCanSource> quiet);

  /// As SocketCanSource::read(). kTimeout only when neither socket had a frame.
  ReadStatus read(CanFrame& frame);

  /// Changes which frames wake the reader: from every frame to `wake`, or
  /// from a split back to every frame (empty `wake`). Throws SocketCanError
  /// (the source stays as it was) or std::logic_error (not from open(), or
  /// from one split to another: go through every frame).
  void set_wake(const std::vector<CanIdFilter>& wake);

  /// Both sockets' counts added up, a closed quiet socket's included
  /// (timeouts and network_down: the waking socket's only).
  [[nodiscard]] SocketCanStats stats() const;
  /// SocketCanSource::refresh_kernel_drops() on both sockets.
  void refresh_kernel_drops() {
    waking_.refresh_kernel_drops();
    if (quiet_) quiet_->refresh_kernel_drops();
  }
  /// Two sockets in use (a quiet one being emptied after set_wake({}) aside).
  [[nodiscard]] bool split() const { return quiet_.has_value() && !quiet_retiring_; }
  /// The wake IDs set by open()/set_wake() (empty for the two-socket constructor).
  [[nodiscard]] const std::vector<CanIdFilter>& wake() const { return wake_; }
  /// How often the waking socket stayed silent for read_timeout while quiet
  /// frames were waiting: the wake IDs no longer complete the samples.
  [[nodiscard]] std::uint64_t waking_silences() const { return waking_silences_; }
  /// Frames both sockets received while the split changed, handed out once.
  [[nodiscard]] std::uint64_t duplicates_skipped() const { return duplicates_skipped_; }
  [[nodiscard]] const std::string& iface() const { return waking_.iface(); }
  void set_read_timeout(std::chrono::milliseconds timeout) {
    read_timeout_ = timeout;
    waking_.set_read_timeout(timeout);
  }

 private:
  /// A frame and its receive stamp at full resolution: at vcan speed two
  /// frames can arrive within one microsecond.
  struct Stamped {
    CanFrame frame;
    std::int64_t stamp_ns = 0;
  };

  /// Reads the next quiet frame into quiet_next_ if it is empty and one is
  /// queued; counts short reads; closes a retired quiet socket once empty.
  void pull_quiet();
  /// Reads the waking socket: waiting (read_timeout), or not at all.
  ReadStatus read_waking(bool wait);
  ReadStatus hand_out(std::optional<Stamped>& slot, CanFrame& frame);
  /// The same skb through both sockets: same stamp, ID and payload.
  [[nodiscard]] static bool same_frame(const Stamped& a, const Stamped& b);
  [[nodiscard]] static SocketCanOptions quiet_options(const SocketCanOptions& base, const std::vector<CanIdFilter>& wake);

  SocketCanSource waking_;
  std::optional<SocketCanSource> quiet_;
  std::optional<SocketCanOptions> options_;  ///< set by open(): set_wake() can open a quiet socket
  std::vector<CanIdFilter> wake_;
  std::chrono::milliseconds read_timeout_;
  std::optional<Stamped> held_;          ///< waking frame, until the quiet frames before it are out
  std::optional<Stamped> quiet_next_;    ///< the oldest quiet frame not handed out
  std::optional<ReadStatus> deferred_;   ///< waking socket's status, after the frames queued before it
  std::int64_t deferred_at_ns_ = 0;      ///< [ns] when deferred_ was read: frames stamped later come after it
  bool quiet_flowing_ = false;           ///< no waking frame for read_timeout: quiet frames as they come
  bool quiet_retiring_ = false;          ///< back to one socket: the quiet one is read until empty
  std::uint64_t truncated_pending_ = 0;  ///< quiet kTruncated results not reported yet
  std::uint64_t duplicates_skipped_ = 0;
  std::uint64_t waking_silences_ = 0;
  SocketCanStats closed_quiet_;          ///< counts of quiet sockets already closed
};

}  // namespace resolver
