#include "drivers/socketcan/split_wake_source.h"

#include <cerrno>
#include <utility>

namespace resolver {

SplitWakeSource SplitWakeSource::open(const SocketCanOptions& options, const std::vector<CanIdFilter>& wake) {
  if (!options.filters.empty()) {
    throw SocketCanError("open (split wake-up sockets)", options.iface, EINVAL,
                         "receive filters and wake IDs cannot be combined");
  }
  if (wake.empty()) return SplitWakeSource(SocketCanSource::open(options), std::nullopt);
  // The quiet socket first: from its bind on it receives every non-waking
  // frame, so none can slip between the two binds unseen. (A waking frame in
  // that instant reaches neither; the waking socket is bound microseconds
  // later, before the caller reads anything, and the bus is idle at start-up.)
  SocketCanOptions quiet_options = options;
  quiet_options.receive_error_frames = false;  // error frames must wake the reader
  quiet_options.join_filters = true;           // "not A and not B", not "not A or not B"
  for (CanIdFilter f : wake) {
    f.inverted = true;
    quiet_options.filters.push_back(f);
  }
  SocketCanSource quiet = SocketCanSource::open(quiet_options);
  SocketCanOptions waking_options = options;
  waking_options.filters = wake;
  return SplitWakeSource(SocketCanSource::open(waking_options), std::move(quiet));
}

SplitWakeSource::SplitWakeSource(SocketCanSource waking, std::optional<SocketCanSource> quiet)
    : waking_(std::move(waking)), quiet_(std::move(quiet)) {
  if (quiet_) quiet_->set_read_timeout(std::chrono::milliseconds(0));  // drained, never waited on
}

void SplitWakeSource::drain_quiet() {
  if (!quiet_) return;
  CanFrame frame;
  for (;;) {
    const ReadStatus s = quiet_->read(frame);
    if (s == ReadStatus::kFrame) {
      quiet_frames_.push_back(Stamped{frame, quiet_->last_stamp_ns()});
    } else if (s == ReadStatus::kTruncated) {
      ++truncated_pending_;
    } else {
      // kTimeout: empty. kNetworkDown/kDeviceGone also reach the waking
      // socket, which reports them; kInterrupted: the next read() drains on.
      return;
    }
  }
}

ReadStatus SplitWakeSource::pop_quiet(CanFrame& frame) {
  frame = quiet_frames_.front().frame;
  quiet_frames_.pop_front();
  return ReadStatus::kFrame;
}

ReadStatus SplitWakeSource::read(CanFrame& frame) {
  if (!quiet_) return waking_.read(frame);
  for (;;) {
    if (truncated_pending_ > 0) {
      --truncated_pending_;
      return ReadStatus::kTruncated;
    }
    if (held_) {
      // Quiet frames that arrived before the waking frame go first. Equal
      // stamps: the quiet one, as the frames of a sample precede the one
      // that completes it.
      if (quiet_frames_.empty()) drain_quiet();
      if (!quiet_frames_.empty() && quiet_frames_.front().stamp_ns <= held_->stamp_ns) return pop_quiet(frame);
      frame = held_->frame;
      held_.reset();
      return ReadStatus::kFrame;
    }
    if (deferred_) {
      if (!quiet_frames_.empty()) return pop_quiet(frame);
      const ReadStatus s = *deferred_;
      deferred_.reset();
      return s;
    }
    CanFrame waking_frame;
    const ReadStatus s = waking_.read(waking_frame);
    switch (s) {
      case ReadStatus::kFrame:
        held_ = Stamped{waking_frame, waking_.last_stamp_ns()};
        continue;
      case ReadStatus::kTimeout:
        // No waking frame for read_timeout: hand out what the quiet socket has.
        drain_quiet();
        if (!quiet_frames_.empty()) return pop_quiet(frame);
        if (truncated_pending_ > 0) continue;
        return s;
      case ReadStatus::kNetworkDown:
      case ReadStatus::kDeviceGone:
        // The caller may drop this source: first everything already received.
        drain_quiet();
        deferred_ = s;
        continue;
      case ReadStatus::kInterrupted:
      case ReadStatus::kTruncated:
        return s;
    }
    return s;
  }
}

SocketCanStats SplitWakeSource::stats() const {
  SocketCanStats sum = waking_.stats();
  if (!quiet_) return sum;
  const SocketCanStats& q = quiet_->stats();
  sum.frames += q.frames;
  sum.fd_frames += q.fd_frames;
  sum.error_frames += q.error_frames;
  sum.kernel_drops += q.kernel_drops;
  sum.truncated += q.truncated;
  return sum;
}

}  // namespace resolver
