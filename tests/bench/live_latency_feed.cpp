#include "tests/bench/live_latency_feed.h"

#include <linux/can/error.h>
#include <poll.h>
#include <sys/socket.h>
#include <time.h>

#include <algorithm>
#include <cerrno>
#include <cmath>

#include "drivers/socketcan/can_wire.h"

namespace resolver::bench_live {
namespace {

constexpr double kRpm = 200.0;            // Hwang's test speed [r/min]
constexpr double kBenchInfoHz = 10.0;     // BENCH_INFO rate (DESIGN 4)
constexpr double kFramesPerSample = 3.0;  // sample + currents + reference
constexpr std::int64_t kNsPerS = 1'000'000'000;

SimConfig sim_config(double frames_per_s, double seconds) {
  SimConfig c;
  // Whole Hz (BENCH_INFO carries a u16): 8000 frames/s -> 2663 Hz -> 7999 frames/s.
  c.sample_rate_hz = std::max(1.0, std::round((frames_per_s - kBenchInfoHz) / kFramesPerSample));
  // A margin so the feed outlasts the paced run even if the sender catches up.
  c.profile = {{seconds + 5.0, kRpm, kRpm}};
  c.chain.amplitude_imbalance.alpha = 0.003;
  return c;
}

std::int64_t mono_ns() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * kNsPerS + ts.tv_nsec;
}

void sleep_until_ns(std::int64_t t) {
  timespec ts{};
  ts.tv_sec = static_cast<time_t>(t / kNsPerS);
  ts.tv_nsec = static_cast<long>(t % kNsPerS);
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
  }
}

CanFrame error_frame() {
  // A controller "RX warning" error frame (linux/can/error.h), as a CAN
  // controller reports when its receive error counter passes 96.
  CanFrame f;
  f.error = true;
  f.id = CAN_ERR_CRTL;
  f.len = CAN_ERR_DLC;
  f.data[1] = CAN_ERR_CRTL_RX_WARNING;
  return f;
}

}  // namespace

FrameFeed::FrameFeed(double frames_per_s, double seconds) : sim_(sim_config(frames_per_s, seconds)) {
  pending_.reserve(8);
}

bool FrameFeed::next(CanFrame& out) {
  if (at_ == pending_.size()) {
    pending_.clear();
    at_ = 0;
    SimSample s{};
    if (!sim_.next(s)) return false;
    sim_.append_frames(s, pending_);
  }
  out = pending_[at_++];
  return true;
}

bool send_one(int fd, const CanFrame& frame, SendCounts& counts) {
  CanWireImage image{};
  const std::size_t size = encode_wire_frame(frame, image);
  ++counts.attempted;
  // ENOBUFS: the CAN_RAW socket's send buffer or the device queue is full;
  // CAN_RAW does not signal POLLOUT for it, so retry every 1 ms (~8 frames of
  // bus time) for up to 100 ms before counting the frame as failed.
  for (int tries = 0;; ++tries) {
    const ssize_t n = ::send(fd, image.data(), size, MSG_NOSIGNAL);
    if (n == static_cast<ssize_t>(size)) {
      ++counts.sent;
      if (frame.error) ++counts.error_sent;
      return true;
    }
    const int err = n < 0 ? errno : EIO;
    if (err == EINTR) continue;
    if ((err == ENOBUFS || err == EAGAIN) && tries < 100) {
      ::poll(nullptr, 0, 1);
      continue;
    }
    if (err == ENETDOWN) {
      ++counts.failed_down;
    } else {
      ++counts.failed_other;
    }
    return false;
  }
}

SendCounts send_paced(int fd, FrameFeed& feed, const PaceConfig& cfg, const std::atomic<bool>& stop) {
  SendCounts counts;
  const int burst = std::max(1, cfg.burst);
  const double period_ns = 1e9 / cfg.frames_per_s;
  const auto total = static_cast<std::uint64_t>(cfg.seconds * cfg.frames_per_s);
  const auto error_every = static_cast<std::uint64_t>(cfg.error_every_s * cfg.frames_per_s);
  const CanFrame err_frame = error_frame();
  CanFrame frame;
  const std::int64_t t0 = mono_ns();
  std::uint64_t i = 0;
  bool more = true;
  while (more && i < total && !stop.load(std::memory_order_relaxed)) {
    // Absolute schedule: a late wake-up is caught up by the next burst rather
    // than shifting every later frame (the bus does not slow down either).
    const std::int64_t due = t0 + static_cast<std::int64_t>(static_cast<double>(i) * period_ns);
    sleep_until_ns(due);
    const double late_ns = static_cast<double>(mono_ns() - due);
    if (late_ns > period_ns) ++counts.late_wakeups;
    counts.max_late_us = std::max(counts.max_late_us, late_ns * 1e-3);
    for (int b = 0; b < burst && i < total; ++b, ++i) {
      more = feed.next(frame);
      if (!more) break;
      send_one(fd, frame, counts);
      if (error_every > 0 && i % error_every == error_every - 1) send_one(fd, err_frame, counts);
    }
  }
  counts.seconds = static_cast<double>(mono_ns() - t0) * 1e-9;
  return counts;
}

}  // namespace resolver::bench_live
