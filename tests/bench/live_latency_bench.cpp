// Live latency benchmark: how long resolverd's live path takes from a frame's
// arrival to the return of the LCM publish it causes, at full bus rate, and
// what share of one core that costs. Prints a table; not a timed test.
//
//   writer thread: default-bench frames (BenchSimulator) paced at --rate frames/s
//       │ struct can_frame bytes
//       ▼
//   host:  socketpair(AF_UNIX, SOCK_SEQPACKET) ── SocketCanSource::adopt
//   guest: vcan0 (CAN_RAW, --iface) ────────────── SocketCanSource::open
//       │ recvmsg + SO_TIMESTAMPNS (the kernel stamps at send / netif_rx)
//       ▼
//   this thread: the per-frame work of run_live (live_runner.cpp): read,
//       Pipeline::feed, set_kernel_drops, tick; LcmOutput behind a sink that
//       notes when each publish returned.
//
// The host kernel here has no PF_CAN, so the socket pair stands in for the
// CAN_RAW socket: the driver's real read path (poll, recvmsg, cmsg parsing,
// wire decoding) runs unchanged on it. run_live itself is not called because
// it can only open an interface by name; the loop below is its hot path.
//
// Latency "arrival": the frame's kernel receive timestamp (CLOCK_REALTIME,
// 1 us resolution as the driver reports it), so the time the frame waited in
// the socket queue and the reader's wake-up are included. "recvmsg": from the
// return of SocketCanSource::read, the in-process part only. Only frames that
// published something (the one completing a sample: angle_t + dq_t, plus
// health_t once a second) have a publish latency; "all frames" is arrival to
// the end of Pipeline::feed for every frame.
#include <pthread.h>
#include <sched.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <time.h>

#include <CLI/CLI.hpp>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <limits>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "daemon/app/daemon_config.h"
#include "daemon/app/lcm_output.h"
#include "daemon/app/pipeline.h"
#include "daemon/app/wake_planner.h"
#include "drivers/socketcan/socketcan_source.h"
#include "drivers/socketcan/split_wake_source.h"
#include "tests/bench/live_latency_feed.h"
#include "tests/bench/live_latency_stats.h"

namespace {

using resolver::bench_live::FrameFeed;
using resolver::bench_live::PaceConfig;
using resolver::bench_live::RunResult;
using resolver::bench_live::SendCounts;

struct Options {
  double seconds = 30.0;
  int runs = 1;
  double rate = 8000.0;
  int burst = 1;
  double warmup = 1.0;
  std::string lcm = "memq://";
  std::string iface;  // empty: socket pair on the host
  std::string json;
  std::string config;    // resolverd config file; "" = the built-in defaults
  std::vector<std::string> effects;  // resolver-sim specs added to the stream (FrameFeed)
  int sender_fifo = 50;  // SCHED_FIFO priority of the sending thread; 0 = normal
  int reader_fifo = 0;   // of the reading thread (resolverd's unit sets none)
  bool read_only = false;  // the floor: read every frame, no pipeline, no publish
  std::vector<std::uint32_t> wake_ids;  // resolverd's [can] wake_ids
};

std::int64_t realtime_ns() {
  timespec ts{};
  clock_gettime(CLOCK_REALTIME, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

double cpu_clock_s(clockid_t clock) {
  timespec ts{};
  if (clock_gettime(clock, &ts) != 0) return std::numeric_limits<double>::quiet_NaN();
  return static_cast<double>(ts.tv_sec) + static_cast<double>(ts.tv_nsec) * 1e-9;
}

double thread_cpu_s() { return cpu_clock_s(CLOCK_THREAD_CPUTIME_ID); }

/// The interface's rx_dropped counter (frames the kernel dropped before any
/// socket), 0 where sysfs cannot be read.
std::uint64_t rx_dropped(const std::string& iface) {
  std::ifstream in("/sys/class/net/" + iface + "/statistics/rx_dropped");
  std::uint64_t n = 0;
  in >> n;
  return n;
}

/// [s] CPU of every thread of this process except the sender: the reader and
/// the threads the pipeline starts (the live model fit).
double daemon_cpu_s(clockid_t sender_clock) {
  return cpu_clock_s(CLOCK_PROCESS_CPUTIME_ID) - cpu_clock_s(sender_clock);
}

/// Forwards to LCM and remembers when the last publish returned, so the
/// reader can tell which frame published and when its output left.
class TimingSink final : public resolver::OutputSink {
 public:
  explicit TimingSink(resolver::OutputSink& out) : out_(out) {}
  void publish(const resolver::angle_t& m) override { note(out_, m); }
  void publish(const resolver::dq_t& m) override { note(out_, m); }
  void publish(const resolver::estimate_t& m) override { note(out_, m); }
  void publish(const resolver::model_fit_t& m) override { note(out_, m); }
  void publish(const resolver::health_t& m) override { note(out_, m); }
  [[nodiscard]] std::uint64_t count() const { return count_; }
  [[nodiscard]] std::int64_t last_return_ns() const { return last_return_ns_; }

 private:
  template <typename T>
  void note(resolver::OutputSink& out, const T& m) {
    out.publish(m);
    last_return_ns_ = realtime_ns();
    ++count_;
  }
  resolver::OutputSink& out_;
  std::uint64_t count_ = 0;
  std::int64_t last_return_ns_ = 0;
};

/// The reading end and the writing end of one run.
struct Endpoints {
  resolver::SplitWakeSource reader;
  resolver::UniqueFd writer_owned;  // socket pair: the other end
  resolver::UniqueFd quiet_writer;  // socket pair, --wake-ids: the quiet socket's other end
  std::optional<resolver::SocketCanSource> writer_can;  // vcan: a second CAN_RAW socket
  [[nodiscard]] int writer_fd() const { return writer_can ? writer_can->fd() : writer_owned.get(); }
};

/// A socket pair whose reading end gets what open() enables on a CAN_RAW
/// socket; AF_UNIX stamps each datagram when it is sent (there is no receive
/// interrupt to stamp at).
std::pair<resolver::SocketCanSource, resolver::UniqueFd> stamped_pair(const char* name) {
  int fds[2] = {-1, -1};
  if (::socketpair(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0, fds) < 0) {
    throw resolver::SocketCanError("socketpair(AF_UNIX, SOCK_SEQPACKET)", name, errno);
  }
  const int on = 1;
  ::setsockopt(fds[0], SOL_SOCKET, SO_TIMESTAMPNS, &on, sizeof on);
  ::setsockopt(fds[0], SOL_SOCKET, SO_RXQ_OVFL, &on, sizeof on);
  return {resolver::SocketCanSource::adopt(fds[0], name), resolver::UniqueFd(fds[1])};
}

Endpoints open_endpoints(const Options& o) {
  if (!o.iface.empty()) {
    resolver::SocketCanOptions ro;
    ro.iface = o.iface;
    ro.receive_buffer_bytes = resolver::CanOptions{}.receive_buffer_bytes;  // resolverd's default
    resolver::SocketCanOptions wo;
    wo.iface = o.iface;
    wo.receive_error_frames = false;
    return Endpoints{resolver::SplitWakeSource::open(ro, resolver::exact_id_filters(o.wake_ids)), resolver::UniqueFd(),
                     resolver::UniqueFd(), resolver::SocketCanSource::open(wo)};
  }
  auto [reader, writer] = stamped_pair("sockpair0");
  if (o.wake_ids.empty()) {
    return Endpoints{resolver::SplitWakeSource(std::move(reader), std::nullopt), std::move(writer),
                     resolver::UniqueFd(), std::nullopt};
  }
  // The sender routes by ID what the kernel's filters would (PaceConfig::quiet_fd).
  auto [quiet_reader, quiet_writer] = stamped_pair("sockpair0");
  return Endpoints{resolver::SplitWakeSource(std::move(reader), std::move(quiet_reader)), std::move(writer),
                   std::move(quiet_writer), std::nullopt};
}

RunResult run_once(const Options& o) {
  resolver::DaemonConfig config = o.config.empty() ? resolver::DaemonConfig{} : resolver::load_daemon_config(o.config);
  config.lcm_url = o.lcm;
  resolver::LcmOutput lcm(o.lcm, config.channels);
  TimingSink sink(lcm);
  resolver::Pipeline pipeline(config, sink, std::cerr);
  Endpoints ends = open_endpoints(o);
  FrameFeed feed(o.rate, o.effects);

  RunResult r;
  const auto expected = static_cast<std::size_t>(o.rate * o.seconds * 1.05) + 64;
  r.publish_kernel_us.reserve(expected / 3 + 64);
  r.publish_read_us.reserve(expected / 3 + 64);
  r.all_kernel_us.reserve(expected);

  std::atomic<bool> stop{false};
  std::atomic<bool> writer_done{false};
  SendCounts sent;
  PaceConfig pace;
  pace.frames_per_s = o.rate;
  pace.burst = o.burst;
  pace.seconds = o.seconds;
  pace.fifo_priority = o.sender_fifo;
  if (ends.quiet_writer.valid()) {
    pace.quiet_fd = ends.quiet_writer.get();
    pace.wake_ids = o.wake_ids;
  }
  constexpr std::uint32_t kEndMarkerId = 0x7FF;  // vcan: the last frame of a run (an unknown ID)
  std::atomic<bool> marker_wanted{false};
  std::thread writer([&] {
    sent = resolver::bench_live::send_paced(ends.writer_fd(), feed, pace, stop);
    // Socket pair: closing the writing end is the end of stream for the reader
    // (0-byte read + POLLHUP -> kDeviceGone); shutdown(SHUT_WR) would give no POLLHUP.
    ends.quiet_writer.reset();
    ends.writer_owned.reset();
    writer_done.store(true);
    if (ends.writer_can) {
      // The kernel reports receive-queue drops (SO_RXQ_OVFL) only with a delivered
      // frame: one end marker (an unknown_id reject) carries the final count. It is
      // sent once the reader has found its queue empty: sent at once, a reader far
      // behind (a starved guest) had its queue full and the marker was dropped with
      // the last frames, whose loss then went uncounted (CI: 4464 frames "LOST").
      while (!marker_wanted.load() && !stop.load()) std::this_thread::sleep_for(std::chrono::milliseconds(2));
      resolver::CanFrame marker;
      marker.id = kEndMarkerId;
      marker.len = 1;
      if (!stop.load()) resolver::bench_live::send_one(ends.writer_fd(), marker, sent);
    }
    // Stay alive until the reader has read this thread's CPU clock, which is
    // invalid once the thread has exited.
    while (!stop.load()) std::this_thread::sleep_for(std::chrono::milliseconds(2));
  });

  using Clock = resolver::Pipeline::Clock;
  const double warmup = std::min(o.warmup, o.seconds / 4.0);
  std::optional<Clock::time_point> first_frame;
  std::optional<Clock::time_point> window_start;
  Clock::time_point last_frame{};
  clockid_t sender_clock{};
  if (::pthread_getcpuclockid(writer.native_handle(), &sender_clock) != 0) sender_clock = CLOCK_THREAD_CPUTIME_ID;
  const std::uint64_t rx_dropped_start = o.iface.empty() ? 0 : rx_dropped(o.iface);
  double cpu_start = thread_cpu_s();
  double daemon_cpu_start = daemon_cpu_s(sender_clock);
  rusage ru_start{};
  getrusage(RUSAGE_THREAD, &ru_start);
  resolver::CanFrame frame;
  // The end of a vcan run is its end marker, asked for at the first quiet read after the
  // sender finished (the receive queue is empty then, so it cannot be dropped): one
  // interface delivers in order, so every frame sent before it has been read or counted
  // as a drop once it is read. Quiet reads end only a run whose marker never came (10 s
  // on vcan; a socket pair ends when the writer closes it).
  const int quiet_reads_at_end = ends.writer_can ? 100 : 5;
  int quiet_after_end = 0;
  bool end_marker = false;
  for (;;) {
    const resolver::ReadStatus status = ends.reader.read(frame);
    if (status == resolver::ReadStatus::kFrame) {
      const Clock::time_point t_read = Clock::now();
      const std::int64_t read_ns = realtime_ns();
      const std::uint64_t before = sink.count();
      if (o.read_only) {
        ++r.frames_seen_read_only;
      } else {
        pipeline.feed(frame, 0, t_read);
      }
      const std::int64_t done_ns = realtime_ns();
      ++r.frames_read;
      last_frame = t_read;
      if (!first_frame) first_frame = t_read;
      if (!window_start && t_read - *first_frame >= std::chrono::duration<double>(warmup)) {
        window_start = t_read;
        cpu_start = thread_cpu_s();
        daemon_cpu_start = daemon_cpu_s(sender_clock);
        getrusage(RUSAGE_THREAD, &ru_start);
      }
      if (window_start) {
        const double arrival_us = static_cast<double>(frame.timestamp_us);
        r.all_kernel_us.push_back(static_cast<float>(static_cast<double>(done_ns) * 1e-3 - arrival_us));
        if (sink.count() != before) {
          // All on CLOCK_REALTIME, the clock of the kernel's stamp.
          const double ret_us = static_cast<double>(sink.last_return_ns()) * 1e-3;
          r.publish_kernel_us.push_back(static_cast<float>(ret_us - arrival_us));
          r.publish_read_us.push_back(static_cast<float>(static_cast<double>(sink.last_return_ns() - read_ns) * 1e-3));
        }
      }
      end_marker = ends.writer_can && frame.id == kEndMarkerId;
    } else if (status == resolver::ReadStatus::kDeviceGone) {  // socket pair closed by the writer
      break;
    } else if (status == resolver::ReadStatus::kTimeout && writer_done.load()) {
      marker_wanted.store(true);
      if (++quiet_after_end >= quiet_reads_at_end) break;
    }
    if (status != resolver::ReadStatus::kTimeout) quiet_after_end = 0;
    pipeline.set_kernel_drops(static_cast<std::int64_t>(ends.reader.stats().kernel_drops));
    pipeline.tick(realtime_ns() / 1000);
    if (end_marker) break;  // its drop count is in the pipeline's now
  }
  const double cpu_end = thread_cpu_s();
  // Before the join: the sender's clock is valid only while it runs, and it
  // runs until the reader has seen the end of the stream.
  const double daemon_cpu_end = daemon_cpu_s(sender_clock);
  rusage ru_end{};
  getrusage(RUSAGE_THREAD, &ru_end);
  stop.store(true);
  writer.join();
  pipeline.finish();

  r.sent = sent;
  r.wall_s = window_start ? std::chrono::duration<double>(last_frame - *window_start).count() : 0.0;
  r.cpu_s = cpu_end - cpu_start;
  r.daemon_cpu_s = daemon_cpu_end - daemon_cpu_start;
  r.ctx_switches = (ru_end.ru_nvcsw - ru_start.ru_nvcsw) + (ru_end.ru_nivcsw - ru_start.ru_nivcsw);
  r.kernel_drops = ends.reader.stats().kernel_drops;
  if (!o.iface.empty()) r.iface_drops = rx_dropped(o.iface) - rx_dropped_start;
  r.frames_seen = o.read_only ? r.frames_seen_read_only : pipeline.intake().stats().frames_seen;
  r.frames_decoded = pipeline.intake().stats().frames_decoded;
  r.rejects = pipeline.intake().rejects().total();
  r.lcm_failures = lcm.publish_failures();
  if (const resolver::LiveModelFit* fit = pipeline.model_fit()) {
    r.windows_fitted = fit->counters().windows_fitted;
    r.windows_insufficient = fit->counters().windows_insufficient;
    r.windows_skipped = fit->counters().windows_skipped;
  }
  r.sample_rate_hz = feed.sample_rate_hz();
  r.rpm = feed.rpm();
  return r;
}

int run(int argc, char** argv) {
  CLI::App app{"Live latency of resolverd's SocketCAN read path: frame arrival -> LCM publish return, and CPU share.\n"
               "Host (no PF_CAN): frames go through socketpair(AF_UNIX, SOCK_SEQPACKET) into SocketCanSource::adopt.\n"
               "With --iface vcan0 (vcan guest): a real CAN_RAW socket. See docs/PERFORMANCE.md, 'Live latency'."};
  Options o;
  app.add_option("--seconds", o.seconds, "traffic per run [s]")->check(CLI::PositiveNumber);
  app.add_option("--runs", o.runs, "runs; the table's last row is the median of each column")->check(CLI::PositiveNumber);
  app.add_option("--rate", o.rate, "frames per second (8000 ~ a saturated 1 Mbit/s bus)")->check(CLI::PositiveNumber);
  app.add_option("--burst", o.burst, "frames sent back to back per sender wake-up (1 = evenly spaced)")
      ->check(CLI::PositiveNumber);
  app.add_option("--warmup", o.warmup, "first seconds of each run not counted (capped at a quarter of the run) [s]");
  app.add_option("--lcm", o.lcm, "LCM URL of the output (memq://, or udpm://239.255.76.67:7667?ttl=0)");
  app.add_option("--iface", o.iface, "read a real SocketCAN interface (vcan0) instead of a socket pair");
  app.add_option("--json", o.json, "also write the results as JSON to this file");
  app.add_option("--config", o.config, "resolverd config (TOML) for the pipeline, e.g. decimation or [model] enabled = false");
  app.add_option("--effect", o.effects,
                 "resolver-sim effect spec added to the stream (repeatable), e.g. quadrature:beta=0.01: one the "
                 "default model lacks, so every live window ranks its candidates");
  app.add_option("--sender-fifo", o.sender_fifo,
                 "SCHED_FIFO priority of the sending thread, so host load does not bunch the frames; 0 = normal");
  app.add_option("--reader-fifo", o.reader_fifo,
                 "SCHED_FIFO priority of the reading (daemon) thread; 0 = normal, as resolverd runs by default");
  app.add_flag("--read-only", o.read_only,
               "the floor: only SocketCanSource::read each frame (no pipeline, no publish), i.e. what waking once "
               "per frame costs on this machine");
  app.add_option("--wake-ids", o.wake_ids,
                 "resolverd's [can] wake_ids: only these frame IDs wake the reader, the others wait in a second "
                 "socket (host: a second socket pair, the sender routes by ID as the kernel's filters would), "
                 "e.g. 0x102")
      ->expected(1, 16);
  CLI11_PARSE(app, argc, argv);

  std::string reader_sched = "SCHED_OTHER";
  if (o.reader_fifo > 0) {
    sched_param sp{};
    sp.sched_priority = o.reader_fifo;
    const bool ok = ::pthread_setschedparam(::pthread_self(), SCHED_FIFO, &sp) == 0;
    reader_sched = ok ? "SCHED_FIFO " + std::to_string(o.reader_fifo) : "SCHED_OTHER (SCHED_FIFO refused)";
  }

  std::vector<RunResult> runs;
  try {
    for (int i = 0; i < o.runs; ++i) runs.push_back(run_once(o));
  } catch (const std::exception& e) {
    std::cerr << "live_latency_bench: " << e.what() << "\n";
    return 2;
  }
  std::string split =
      o.wake_ids.empty() ? "" : "; split: only " + resolver::WakePlanner::describe(o.wake_ids) + " wake the reader";
  for (const std::string& e : o.effects) split += "; stream + " + e;
  const resolver::bench_live::Setup setup{(o.iface.empty() ? "socketpair(AF_UNIX, SOCK_SEQPACKET) -> SocketCanSource::adopt"
                                                           : o.iface + " (CAN_RAW) -> SocketCanSource::open") + split,
                                          o.read_only ? std::string("none (--read-only: read path only)")
                                                      : o.lcm + (o.config.empty() ? "" : ", config " + o.config), o.rate, o.burst, o.seconds, std::min(o.warmup, o.seconds / 4.0),
                                          reader_sched};
  resolver::bench_live::print_table(std::cout, setup, runs);
  if (!o.json.empty()) {
    std::ofstream out(o.json);
    resolver::bench_live::write_json(out, setup, runs);
  }
  // Not a timing test: only a lost or mangled frame makes this fail.
  return resolver::bench_live::all_frames_accounted(runs) ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    std::cerr << "live_latency_bench: " << e.what() << "\n";
  } catch (...) {
    std::cerr << "live_latency_bench: unknown exception\n";
  }
  return 2;
}
