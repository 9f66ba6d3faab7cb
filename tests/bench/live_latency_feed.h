// Frame supply for the live-latency benchmark and the vcan soak: default-bench
// frames from the simulator, sent as raw `struct can_frame` images at a fixed
// frame rate on a datagram socket (an AF_UNIX socket pair on the host, a
// CAN_RAW socket on vcan in the guest).
//
// A saturated 1 Mbit/s bus carries ~8000 classic 8-byte frames/s back to back,
// so the sender spaces frames evenly (125 us at 8000/s) instead of copying the
// simulator's timestamps, and the simulator's control rate is chosen so its
// own frame rate matches (3 frames per sample + BENCH_INFO at 10 Hz).
#pragma once

#include <atomic>
#include <cstdint>
#include <string>
#include <vector>

#include "drivers/can_frame.h"
#include "tools/sim/bench_simulator.h"

namespace resolver::bench_live {

/// Endless stream of default-layout frames (alpha = 0.003). The simulator
/// runs once, for kLoopRevolutions mechanical revolutions of 768 samples each
/// (the speed is chosen for that: ~208 r/min at 8000 frames/s), and the frames
/// are then replayed in a loop: 768 is a multiple of 256, so the u8 counters
/// and the angles run on seamlessly across the seam. Generating on the fly
/// would cost the sender more CPU than the reader it measures (the simulator's
/// maths is slow under emulation in the vcan guest).
class FrameFeed {
 public:
  static constexpr int kSamplesPerRevolution = 768;
  static constexpr int kLoopRevolutions = 4;

  /// `effects`: resolver-sim specs on top of alpha = 0.003 ("quadrature:beta=0.01"), e.g.
  /// one the daemon's model lacks, so that every live window ranks its candidates.
  explicit FrameFeed(double frames_per_s, const std::vector<std::string>& effects = {});
  /// The next frame in bus order (endless).
  const CanFrame& next() {
    const CanFrame& f = frames_[at_];
    at_ = at_ + 1 == frames_.size() ? 0 : at_ + 1;
    return f;
  }
  [[nodiscard]] double sample_rate_hz() const { return sample_rate_hz_; }
  [[nodiscard]] double rpm() const { return rpm_; }
  [[nodiscard]] std::size_t loop_frames() const { return frames_.size(); }

 private:
  std::vector<CanFrame> frames_;
  std::size_t at_ = 0;
  double sample_rate_hz_ = 0.0;
  double rpm_ = 0.0;
};

struct PaceConfig {
  double frames_per_s = 8000.0;
  int burst = 1;                ///< frames sent back to back per wake-up
  double seconds = 10.0;        ///< how long to send
  double error_every_s = 0.0;   ///< inject one CAN error frame this often; 0 = never
  int fifo_priority = 0;        ///< > 0: run the sending thread SCHED_FIFO at this priority
  /// Host stand-in for the kernel's CAN_RAW filters of a split reader
  /// (split_wake_source.h): frames whose ID is not in wake_ids go to
  /// quiet_fd instead of the main fd. -1 = everything to the main fd.
  int quiet_fd = -1;
  std::vector<std::uint32_t> wake_ids;
};

/// What the sender did; every frame it tried to send is in exactly one of
/// sent / failed_down / failed_other.
struct SendCounts {
  std::uint64_t attempted = 0;      ///< data + error frames tried
  std::uint64_t sent = 0;           ///< accepted by the socket (data + error)
  std::uint64_t error_sent = 0;     ///< of `sent`, error frames
  std::uint64_t failed_down = 0;    ///< ENETDOWN: the link was down (never reached a reader)
  std::uint64_t failed_other = 0;   ///< any other send failure (ENOBUFS after retries, ...)
  std::uint64_t late_wakeups = 0;   ///< wake-ups so late that the next one was already due
  double max_late_us = 0.0;         ///< [us] worst wake-up lateness
  double seconds = 0.0;             ///< [s] first to last send
  bool fifo = false;                ///< the sender ran SCHED_FIFO (fifo_priority granted)
};

/// Sends frames from `feed` on `fd` (a connected datagram socket: CAN_RAW or
/// AF_UNIX) at cfg.frames_per_s until cfg.seconds pass or `stop` is set. Blocking sends; ENOBUFS is retried for up to ~100 ms.
SendCounts send_paced(int fd, FrameFeed& feed, const PaceConfig& cfg, const std::atomic<bool>& stop);

/// Sends one frame outside the pacing (end markers); true when accepted.
bool send_one(int fd, const CanFrame& frame, SendCounts& counts);

}  // namespace resolver::bench_live
