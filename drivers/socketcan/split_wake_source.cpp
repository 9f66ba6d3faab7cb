#include "drivers/socketcan/split_wake_source.h"

#include <cerrno>
#include <chrono>
#include <cstring>
#include <stdexcept>
#include <utility>

namespace resolver {
namespace {

/// [ns] CLOCK_REALTIME, the clock of the kernel's receive stamps.
std::int64_t realtime_now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

/// Adds a quiet socket's counts (timeouts and network_down stay the waking
/// socket's: the quiet one is never waited on).
void add_quiet_counts(SocketCanStats& into, const SocketCanStats& quiet) {
  into.frames += quiet.frames;
  into.fd_frames += quiet.fd_frames;
  into.error_frames += quiet.error_frames;
  into.kernel_drops += quiet.kernel_drops;
  into.truncated += quiet.truncated;
}

}  // namespace

SocketCanOptions SplitWakeSource::quiet_options(const SocketCanOptions& base, const std::vector<CanIdFilter>& wake) {
  SocketCanOptions q = base;
  q.receive_error_frames = false;  // error frames must wake the reader
  q.join_filters = true;           // "not A and not B", not "not A or not B"
  q.filters.clear();
  for (CanIdFilter f : wake) {
    f.inverted = true;
    q.filters.push_back(f);
  }
  q.read_timeout = std::chrono::milliseconds(0);  // never waited on
  return q;
}

SplitWakeSource SplitWakeSource::open(const SocketCanOptions& options, const std::vector<CanIdFilter>& wake) {
  if (!options.filters.empty()) {
    throw SocketCanError("open (split wake-up sockets)", options.iface, EINVAL,
                         "receive filters and wake IDs cannot be combined");
  }
  SplitWakeSource source(SocketCanSource::open(options), std::nullopt);
  source.options_ = options;
  if (!wake.empty()) source.set_wake(wake);
  return source;
}

SplitWakeSource::SplitWakeSource(SocketCanSource waking, std::optional<SocketCanSource> quiet)
    : waking_(std::move(waking)), quiet_(std::move(quiet)), read_timeout_(waking_.read_timeout()) {
  if (quiet_) quiet_->set_read_timeout(std::chrono::milliseconds(0));
}

void SplitWakeSource::set_wake(const std::vector<CanIdFilter>& wake) {
  if (!options_) throw std::logic_error("SplitWakeSource::set_wake needs a source made by open()");
  if (wake.empty() && !split()) return;
  if (!wake.empty() && split()) {
    throw std::logic_error("SplitWakeSource::set_wake: from one split to another, go through every frame");
  }
  if (!wake.empty()) {
    // One socket -> two. The quiet socket first, then the waking socket's
    // filters narrowed: a non-waking frame in between reaches both (handed
    // out once, same_frame) rather than neither.
    SocketCanSource quiet = quiet_ ? std::move(*quiet_) : SocketCanSource::open(quiet_options(*options_, wake));
    quiet_.reset();
    if (quiet_retiring_) quiet.set_filters(quiet_options(*options_, wake).filters, true);  // reused while emptying
    waking_.set_filters(wake);
    quiet_ = std::move(quiet);
    quiet_retiring_ = false;
    wake_ = wake;
    return;
  }
  // Two sockets -> one. The waking socket takes every frame first, then the
  // quiet one stops receiving; it is read until empty and closed (pull_quiet).
  waking_.set_filters({});
  quiet_->receive_nothing();
  quiet_retiring_ = true;
  quiet_flowing_ = false;
  wake_.clear();
}

bool SplitWakeSource::same_frame(const Stamped& a, const Stamped& b) {
  return a.stamp_ns == b.stamp_ns && a.frame.id == b.frame.id && a.frame.len == b.frame.len &&
         a.frame.extended == b.frame.extended && a.frame.fd == b.frame.fd &&
         std::memcmp(a.frame.data.data(), b.frame.data.data(), a.frame.len) == 0;
}

void SplitWakeSource::pull_quiet() {
  if (quiet_next_ || !quiet_) return;
  for (;;) {
    CanFrame frame;
    const ReadStatus s = quiet_->read(frame);
    if (s == ReadStatus::kFrame) {
      quiet_next_ = Stamped{frame, quiet_->last_stamp_ns()};
      return;
    }
    if (s == ReadStatus::kTruncated) {
      ++truncated_pending_;
      continue;
    }
    if (s == ReadStatus::kTimeout && quiet_retiring_) {
      // Drops after the last frame it queued show only through SO_MEMINFO;
      // a full queue retired under a saturated bus hides thousands there.
      quiet_->refresh_kernel_drops();
      add_quiet_counts(closed_quiet_, quiet_->stats());
      quiet_.reset();
      quiet_retiring_ = false;
    }
    // The waking socket gets the same ENETDOWN and reports it; on this one
    // the error came ahead of the frames still queued, so read on.
    if (s == ReadStatus::kNetworkDown) continue;
    // kTimeout: empty. kDeviceGone reaches the waking socket too, which
    // reports it; kInterrupted: the next call reads on.
    return;
  }
}

ReadStatus SplitWakeSource::read_waking(bool wait) {
  if (!wait) waking_.set_read_timeout(std::chrono::milliseconds(0));
  CanFrame frame;
  const ReadStatus s = waking_.read(frame);
  if (!wait) waking_.set_read_timeout(read_timeout_);
  if (s == ReadStatus::kFrame) held_ = Stamped{frame, waking_.last_stamp_ns()};
  return s;
}

ReadStatus SplitWakeSource::hand_out(std::optional<Stamped>& slot, CanFrame& frame) {
  frame = slot->frame;
  slot.reset();
  return ReadStatus::kFrame;
}

ReadStatus SplitWakeSource::read(CanFrame& frame) {
  if (!quiet_ && !quiet_next_ && !held_ && !deferred_ && truncated_pending_ == 0) return waking_.read(frame);
  for (;;) {
    if (truncated_pending_ > 0) {
      --truncated_pending_;
      return ReadStatus::kTruncated;
    }
    if (deferred_) {
      // The caller may drop this source after the status: first what both
      // sockets had queued when it came. Only that: under a saturated bus the
      // quiet socket refills as fast as it is read, and waiting for it to be
      // empty held the status back for good while the waking socket overflowed.
      if (!held_ && read_waking(false) == ReadStatus::kTruncated) {
        ++truncated_pending_;
        continue;
      }
      pull_quiet();
      if (held_ && quiet_next_ && same_frame(*quiet_next_, *held_)) {
        ++duplicates_skipped_;
        quiet_next_.reset();
        continue;
      }
      std::optional<Stamped>& first =
          held_ && (!quiet_next_ || held_->stamp_ns < quiet_next_->stamp_ns) ? held_ : quiet_next_;
      if (first && first->stamp_ns <= deferred_at_ns_) return hand_out(first, frame);
      const ReadStatus s = *deferred_;
      deferred_.reset();
      return s;
    }
    if (held_) {
      // Quiet frames that arrived before the waking frame go first. Equal
      // stamps: the same frame through both sockets while the split changed,
      // or else the quiet one, as a sample's frames precede the one completing it.
      pull_quiet();
      if (quiet_next_ && same_frame(*quiet_next_, *held_)) {
        ++duplicates_skipped_;
        quiet_next_.reset();
        continue;
      }
      if (quiet_next_ && quiet_next_->stamp_ns <= held_->stamp_ns) return hand_out(quiet_next_, frame);
      return hand_out(held_, frame);
    }
    ReadStatus s = ReadStatus::kTimeout;
    if (quiet_flowing_) {
      // No waking frame came for read_timeout: quiet frames go out as they
      // come, each after a look (not a wait) at the waking socket.
      pull_quiet();
      if (!quiet_next_) {
        quiet_flowing_ = false;
        continue;
      }
      s = read_waking(false);
      if (s == ReadStatus::kTimeout) return hand_out(quiet_next_, frame);
    } else {
      s = read_waking(true);
    }
    switch (s) {
      case ReadStatus::kFrame:
        continue;  // held_: merge with the quiet frames
      case ReadStatus::kTimeout:
        pull_quiet();
        if (quiet_next_) {
          quiet_flowing_ = true;
          ++waking_silences_;
          return hand_out(quiet_next_, frame);
        }
        if (truncated_pending_ > 0) continue;
        return s;
      case ReadStatus::kNetworkDown:
      case ReadStatus::kDeviceGone:
        deferred_ = s;
        deferred_at_ns_ = realtime_now_ns();
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
  add_quiet_counts(sum, closed_quiet_);
  if (quiet_) add_quiet_counts(sum, quiet_->stats());
  return sum;
}

}  // namespace resolver
