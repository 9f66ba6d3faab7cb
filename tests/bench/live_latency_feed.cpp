#include "tests/bench/live_latency_feed.h"

#include <linux/can/error.h>
#include <poll.h>
#include <pthread.h>
#include <sched.h>
#include <sys/prctl.h>
#include <sys/socket.h>
#include <time.h>

#include <algorithm>
#include <cerrno>
#include <cmath>

#include "drivers/socketcan/can_wire.h"

namespace resolver::bench_live {
namespace {

constexpr double kBenchInfoHz = 10.0;     // BENCH_INFO rate (docs/ARCHITECTURE.md §4)
constexpr double kFramesPerSample = 3.0;  // sample + currents + reference
constexpr std::int64_t kNsPerS = 1'000'000'000;

SimConfig sim_config(double sample_rate_hz, double rpm, int samples, const std::vector<std::string>& effects) {
  SimConfig c;
  c.sample_rate_hz = sample_rate_hz;
  c.profile = {{static_cast<double>(samples) / sample_rate_hz, rpm, rpm}};
  c.chain.set("amplitude_imbalance", "alpha", 0.003);
  for (const std::string& spec : effects) c.chain.apply_spec(spec);  // throws naming a bad spec
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

FrameFeed::FrameFeed(double frames_per_s, const std::vector<std::string>& effects) {
  // Whole Hz (BENCH_INFO carries a u16): 8000 frames/s -> 2663 Hz -> 7999 frames/s.
  sample_rate_hz_ = std::max(1.0, std::round((frames_per_s - kBenchInfoHz) / kFramesPerSample));
  rpm_ = sample_rate_hz_ * 60.0 / kSamplesPerRevolution;
  const int samples = kSamplesPerRevolution * kLoopRevolutions;
  BenchSimulator sim(sim_config(sample_rate_hz_, rpm_, samples, effects));
  frames_.reserve(static_cast<std::size_t>(samples) * 4);
  SimSample s{};
  while (sim.next(s)) sim.append_frames(s, frames_);
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
  // The default timer slack (50 us) would let the kernel defer each wake-up
  // by up to 40 % of a frame period; ask for exact wake-ups on this thread.
  ::prctl(PR_SET_TIMERSLACK, 1UL, 0UL, 0UL, 0UL);
  ::pthread_setname_np(::pthread_self(), "llb-sender");  // tells it apart in perf/top
  if (cfg.fifo_priority > 0) {
    // A bus is not delayed by host load: with SCHED_FIFO the sender's timing
    // stays close to the schedule even while other work fills the cores.
    sched_param sp{};
    sp.sched_priority = cfg.fifo_priority;
    counts.fifo = ::pthread_setschedparam(::pthread_self(), SCHED_FIFO, &sp) == 0;
  }
  const int burst = std::max(1, cfg.burst);
  const double period_ns = 1e9 / cfg.frames_per_s;
  const auto total = static_cast<std::uint64_t>(cfg.seconds * cfg.frames_per_s);
  const auto error_every = static_cast<std::uint64_t>(cfg.error_every_s * cfg.frames_per_s);
  const CanFrame err_frame = error_frame();
  const std::int64_t t0 = mono_ns();
  std::uint64_t i = 0;
  while (i < total && !stop.load(std::memory_order_relaxed)) {
    // Absolute schedule: a late wake-up is caught up by the next burst rather
    // than shifting every later frame (the bus does not slow down either).
    const std::int64_t due = t0 + static_cast<std::int64_t>(static_cast<double>(i) * period_ns);
    sleep_until_ns(due);
    const double late_ns = static_cast<double>(mono_ns() - due);
    if (late_ns > period_ns * burst) ++counts.late_wakeups;  // the next wake-up was due already
    counts.max_late_us = std::max(counts.max_late_us, late_ns * 1e-3);
    for (int b = 0; b < burst && i < total; ++b, ++i) {
      const CanFrame& frame = feed.next();
      const bool quiet = cfg.quiet_fd >= 0 && std::find(cfg.wake_ids.begin(), cfg.wake_ids.end(), frame.id) == cfg.wake_ids.end();
      send_one(quiet ? cfg.quiet_fd : fd, frame, counts);
      if (error_every > 0 && i % error_every == error_every - 1) send_one(fd, err_frame, counts);
    }
  }
  counts.seconds = static_cast<double>(mono_ns() - t0) * 1e-9;
  return counts;
}

}  // namespace resolver::bench_live
