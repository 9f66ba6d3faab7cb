// Results of live_latency_bench runs: exact percentiles, the printed table,
// the targets of the issue ("speed and hardening") and a JSON copy for the
// vcan suite, which reads the guest's numbers from it.
#pragma once

#include <cstdint>
#include <ostream>
#include <string>
#include <vector>

#include "tests/bench/live_latency_feed.h"

namespace resolver::bench_live {

inline constexpr double kTargetP99Us = 100.0;      ///< arrival -> publish return, p99 [us]
inline constexpr double kTargetCpuPercent = 5.0;   ///< of one core

struct RunResult {
  SendCounts sent;
  std::uint64_t frames_read = 0;
  std::vector<float> publish_kernel_us;  ///< [us] kernel stamp -> last publish return, publishing frames
  std::vector<float> publish_read_us;    ///< [us] recvmsg return -> last publish return, publishing frames
  std::vector<float> all_kernel_us;      ///< [us] kernel stamp -> Pipeline::feed return, every frame
  double wall_s = 0.0;                   ///< [s] measured window (after warm-up)
  double cpu_s = 0.0;                    ///< [s] reader thread CPU (user + sys) over the window
  /// [s] every thread but the sender's (reader + the live model fit's thread)
  /// over the window: what resolverd itself would use.
  double daemon_cpu_s = 0.0;
  long ctx_switches = 0;                 ///< reader thread, voluntary + involuntary, over the window
  std::uint64_t kernel_drops = 0;
  /// Frames the kernel dropped before any socket (the interface's rx_dropped:
  /// netif backlog full in a starved guest); 0 on a socket pair.
  std::uint64_t iface_drops = 0;
  std::int64_t frames_seen = 0;
  std::int64_t frames_seen_read_only = 0;  ///< --read-only: frames read and dropped on purpose
  std::int64_t frames_decoded = 0;
  std::int64_t rejects = 0;
  std::uint64_t lcm_failures = 0;
  /// The live model fit's windows over the whole run (LiveModelFit::Counters): what the
  /// fit thread's CPU bought; all 0 with the fit off.
  std::int64_t windows_fitted = 0;
  std::int64_t windows_insufficient = 0;
  std::int64_t windows_skipped = 0;
  double sample_rate_hz = 0.0;
  double rpm = 0.0;
};

struct Setup {
  std::string source;
  std::string lcm;
  double rate = 0.0;
  int burst = 1;
  double seconds = 0.0;
  double warmup = 0.0;
  std::string reader_sched;  ///< scheduling of the daemon-side thread
};

/// One row of the table; also the median row.
struct Row {
  double frames = 0, published = 0;
  double pub_p50 = 0, pub_p99 = 0, pub_max = 0;
  double read_p50 = 0, read_p99 = 0, read_max = 0;
  double all_p99 = 0, all_max = 0;
  double cpu_percent = 0, daemon_cpu_percent = 0, wakeups_per_s = 0;
  double late_wakeups = 0, max_late_us = 0;
};

Row summarize(RunResult& r);  ///< sorts r's latency vectors
Row median_row(const std::vector<Row>& rows);

void print_table(std::ostream& out, const Setup& setup, std::vector<RunResult>& runs);
void write_json(std::ostream& out, const Setup& setup, std::vector<RunResult>& runs);

/// Every frame sent was read or counted as a kernel drop, and the pipeline saw
/// every frame read.
bool all_frames_accounted(const std::vector<RunResult>& runs);

}  // namespace resolver::bench_live
