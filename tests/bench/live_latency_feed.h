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
#include <vector>

#include "drivers/can_frame.h"
#include "tools/sim/bench_simulator.h"

namespace resolver::bench_live {

/// Endless stream of default-layout frames (200 r/min, alpha = 0.003).
class FrameFeed {
 public:
  /// `frames_per_s` sets the simulated control rate; `seconds` how long the
  /// stream lasts before it ends (next() then returns false).
  FrameFeed(double frames_per_s, double seconds);
  /// The next frame in bus order; false when the simulated run is over.
  bool next(CanFrame& out);
  [[nodiscard]] double sample_rate_hz() const { return sim_.config().sample_rate_hz; }

 private:
  BenchSimulator sim_;
  std::vector<CanFrame> pending_;
  std::size_t at_ = 0;
};

struct PaceConfig {
  double frames_per_s = 8000.0;
  int burst = 1;                ///< frames sent back to back per wake-up
  double seconds = 10.0;        ///< how long to send
  double error_every_s = 0.0;   ///< inject one CAN error frame this often; 0 = never
};

/// What the sender did; every frame it tried to send is in exactly one of
/// sent / failed_down / failed_other.
struct SendCounts {
  std::uint64_t attempted = 0;      ///< data + error frames tried
  std::uint64_t sent = 0;           ///< accepted by the socket (data + error)
  std::uint64_t error_sent = 0;     ///< of `sent`, error frames
  std::uint64_t failed_down = 0;    ///< ENETDOWN: the link was down (never reached a reader)
  std::uint64_t failed_other = 0;   ///< any other send failure (ENOBUFS after retries, ...)
  std::uint64_t late_wakeups = 0;   ///< wake-ups more than one frame period after their due time
  double max_late_us = 0.0;         ///< [us] worst wake-up lateness
  double seconds = 0.0;             ///< [s] first to last send
};

/// Sends frames from `feed` on `fd` (a connected datagram socket: CAN_RAW or
/// AF_UNIX) at cfg.frames_per_s until cfg.seconds pass, the feed ends or
/// `stop` is set. Blocking sends; ENOBUFS is retried for up to ~100 ms.
SendCounts send_paced(int fd, FrameFeed& feed, const PaceConfig& cfg, const std::atomic<bool>& stop);

/// Sends one frame outside the pacing (end markers); true when accepted.
bool send_one(int fd, const CanFrame& frame, SendCounts& counts);

}  // namespace resolver::bench_live
