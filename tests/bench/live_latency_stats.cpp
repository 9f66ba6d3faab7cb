#include "tests/bench/live_latency_stats.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

namespace resolver::bench_live {
namespace {

/// Nearest-rank percentile of a sorted vector; 0 when empty.
double pct(const std::vector<float>& sorted, double q) {
  if (sorted.empty()) return 0.0;
  const auto i = static_cast<std::size_t>(std::llround(q * static_cast<double>(sorted.size() - 1)));
  return static_cast<double>(sorted[std::min(i, sorted.size() - 1)]);
}

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 == 1 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

std::string fmt(const char* format, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

void row_line(std::ostream& out, const std::string& label, const Row& w) {
  out << "| " << label << " | " << fmt("%.0f", w.frames) << " | " << fmt("%.0f", w.published) << " | "
      << fmt("%.1f", w.pub_p50) << " | " << fmt("%.1f", w.pub_p99) << " | " << fmt("%.0f", w.pub_max) << " | "
      << fmt("%.1f", w.read_p50) << " | " << fmt("%.1f", w.read_p99) << " | " << fmt("%.0f", w.read_max) << " | "
      << fmt("%.1f", w.all_p99) << " | " << fmt("%.2f", w.cpu_percent) << " | " << fmt("%.2f", w.daemon_cpu_percent)
      << " | " << fmt("%.0f", w.wakeups_per_s)
      << " | " << fmt("%.0f", w.late_wakeups) << " / " << fmt("%.0f", w.max_late_us) << " |\n";
}

const char* verdict(bool ok) { return ok ? "met" : "NOT met"; }

}  // namespace

Row summarize(RunResult& r) {
  for (auto* v : {&r.publish_kernel_us, &r.publish_read_us, &r.all_kernel_us}) std::sort(v->begin(), v->end());
  Row w;
  w.frames = static_cast<double>(r.frames_read);
  w.published = static_cast<double>(r.publish_kernel_us.size());
  w.pub_p50 = pct(r.publish_kernel_us, 0.50);
  w.pub_p99 = pct(r.publish_kernel_us, 0.99);
  w.pub_max = pct(r.publish_kernel_us, 1.0);
  w.read_p50 = pct(r.publish_read_us, 0.50);
  w.read_p99 = pct(r.publish_read_us, 0.99);
  w.read_max = pct(r.publish_read_us, 1.0);
  w.all_p99 = pct(r.all_kernel_us, 0.99);
  w.all_max = pct(r.all_kernel_us, 1.0);
  w.cpu_percent = r.wall_s > 0.0 ? 100.0 * r.cpu_s / r.wall_s : 0.0;
  w.daemon_cpu_percent = r.wall_s > 0.0 ? 100.0 * r.daemon_cpu_s / r.wall_s : 0.0;
  w.wakeups_per_s = r.wall_s > 0.0 ? static_cast<double>(r.ctx_switches) / r.wall_s : 0.0;
  w.late_wakeups = static_cast<double>(r.sent.late_wakeups);
  w.max_late_us = r.sent.max_late_us;
  return w;
}

Row median_row(const std::vector<Row>& rows) {
  auto col = [&](double Row::*m) {
    std::vector<double> v;
    v.reserve(rows.size());
    for (const Row& r : rows) v.push_back(r.*m);
    return median(v);
  };
  Row m;
  for (double Row::*f : {&Row::frames, &Row::published, &Row::pub_p50, &Row::pub_p99, &Row::pub_max, &Row::read_p50,
                         &Row::read_p99, &Row::read_max, &Row::all_p99, &Row::all_max, &Row::cpu_percent, &Row::daemon_cpu_percent,
                         &Row::wakeups_per_s, &Row::late_wakeups, &Row::max_late_us}) {
    m.*f = col(f);
  }
  return m;
}

void print_table(std::ostream& out, const Setup& s, std::vector<RunResult>& runs) {
  std::vector<Row> rows;
  rows.reserve(runs.size());
  for (RunResult& r : runs) rows.push_back(summarize(r));
  const Row m = median_row(rows);
  out << "live latency: frame arrival -> LCM publish return (resolverd's live read path)\n"
      << "  source  " << s.source << ", kernel SO_TIMESTAMPNS as the arrival time\n"
      << "  output  LcmOutput " << s.lcm << "\n"
      << "  traffic " << fmt("%.0f", s.rate) << " frames/s, " << s.burst << " per sender wake-up, default bench layout ("
      << fmt("%.0f", runs.empty() ? 0.0 : runs.front().sample_rate_hz)
      << " Hz x 3 frames + BENCH_INFO 10 Hz, " << fmt("%.0f", runs.empty() ? 0.0 : runs.front().rpm)
      << " r/min, " << FrameFeed::kLoopRevolutions << " revolutions looped), " << fmt("%.1f", s.seconds) << " s per run, first "
      << fmt("%.1f", s.warmup) << " s not counted\n"
      << "  threads reader (daemon side) " << s.reader_sched << ", sender "
      << (runs.empty() || !runs.front().sent.fifo ? "SCHED_OTHER" : "SCHED_FIFO") << "\n\n"
      << "| run | frames | publishing frames | arrival->publish p50 [us] | p99 [us] | max [us] | recvmsg->publish p50 [us] "
         "| p99 [us] | max [us] | all frames arrival->done p99 [us] | CPU reader [% of a core] | CPU all daemon threads [%] | reader wake-ups/s | sender "
         "late wake-ups / max [us] |\n"
      << "|---|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|\n";
  for (std::size_t i = 0; i < rows.size(); ++i) row_line(out, std::to_string(i + 1), rows[i]);
  if (rows.size() > 1) row_line(out, "median", m);
  out << "\n";
  for (std::size_t i = 0; i < runs.size(); ++i) {
    const RunResult& r = runs[i];
    out << "run " << i + 1 << ": sent " << r.sent.sent << " (failed " << r.sent.failed_down + r.sent.failed_other
        << "), read " << r.frames_read << ", kernel drops " << r.kernel_drops << " (+ " << r.iface_drops
        << " before any socket, rx_dropped), frames_seen " << r.frames_seen
        << ", decoded " << r.frames_decoded << ", rejects " << r.rejects << ", LCM publish failures " << r.lcm_failures
        << ", CPU " << fmt("%.3f", r.cpu_s) << " s over " << fmt("%.2f", r.wall_s) << " s; model fit windows: "
        << r.windows_fitted << " fitted, " << r.windows_insufficient << " insufficient, " << r.windows_skipped
        << " skipped (the fit was still running)\n";
  }
  if (m.published == 0) {
    out << "targets: not applicable, nothing was published (--read-only measures the read path's floor)\n";
  } else {
    out << "target p99 arrival->publish <= " << fmt("%.0f", kTargetP99Us) << " us: " << verdict(m.pub_p99 <= kTargetP99Us)
        << " (" << (rows.size() > 1 ? "median " : "") << "p99 " << fmt("%.1f", m.pub_p99) << " us)\n"
        << "target CPU < " << fmt("%.0f", kTargetCpuPercent)
        << " % of a core, all daemon threads: " << verdict(m.daemon_cpu_percent < kTargetCpuPercent) << " ("
        << (rows.size() > 1 ? "median " : "") << fmt("%.2f", m.daemon_cpu_percent) << " %; reading thread alone "
        << fmt("%.2f", m.cpu_percent) << " %)\n";
  }
  out << "frames: " << (all_frames_accounted(runs) ? "every frame sent was read (or counted as a kernel drop)"
                                                   : "LOST FRAMES: sent != read + kernel drops + rx_dropped")
      << "\n";
}

void write_json(std::ostream& out, const Setup& s, std::vector<RunResult>& runs) {
  std::vector<Row> rows;
  rows.reserve(runs.size());
  for (RunResult& r : runs) rows.push_back(summarize(r));
  auto row_json = [&](const Row& w) {
    return "{\"frames\": " + fmt("%.0f", w.frames) + ", \"published\": " + fmt("%.0f", w.published) +
           ", \"pub_p50_us\": " + fmt("%.2f", w.pub_p50) + ", \"pub_p99_us\": " + fmt("%.2f", w.pub_p99) +
           ", \"pub_max_us\": " + fmt("%.1f", w.pub_max) + ", \"read_p50_us\": " + fmt("%.2f", w.read_p50) +
           ", \"read_p99_us\": " + fmt("%.2f", w.read_p99) + ", \"read_max_us\": " + fmt("%.1f", w.read_max) +
           ", \"all_p99_us\": " + fmt("%.2f", w.all_p99) + ", \"all_max_us\": " + fmt("%.1f", w.all_max) +
           ", \"cpu_percent\": " + fmt("%.3f", w.cpu_percent) +
           ", \"daemon_cpu_percent\": " + fmt("%.3f", w.daemon_cpu_percent) + ", \"wakeups_per_s\": " + fmt("%.0f", w.wakeups_per_s) +
           ", \"sender_late_wakeups\": " + fmt("%.0f", w.late_wakeups) +
           ", \"sender_max_late_us\": " + fmt("%.0f", w.max_late_us) + "}";
  };
  out << "{\"source\": \"" << s.source << "\", \"lcm\": \"" << s.lcm << "\", \"rate\": " << s.rate
      << ", \"burst\": " << s.burst << ", \"reader_sched\": \"" << s.reader_sched << "\""
      << ", \"seconds\": " << s.seconds << ", \"runs\": [";
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const RunResult& r = runs[i];
    out << (i ? ", " : "") << "{\"row\": " << row_json(rows[i]) << ", \"sent\": " << r.sent.sent
        << ", \"read\": " << r.frames_read << ", \"kernel_drops\": " << r.kernel_drops << ", \"iface_drops\": " << r.iface_drops
        << ", \"frames_seen\": " << r.frames_seen << ", \"rejects\": " << r.rejects
        << ", \"windows_fitted\": " << r.windows_fitted << ", \"windows_insufficient\": " << r.windows_insufficient
        << ", \"windows_skipped\": " << r.windows_skipped << "}";
  }
  out << "], \"median\": " << row_json(median_row(rows))
      << ", \"all_frames_accounted\": " << (all_frames_accounted(runs) ? "true" : "false") << "}\n";
}

bool all_frames_accounted(const std::vector<RunResult>& runs) {
  return std::all_of(runs.begin(), runs.end(), [](const RunResult& r) {
    return r.frames_read + r.kernel_drops + r.iface_drops == r.sent.sent &&
           r.frames_seen == static_cast<std::int64_t>(r.frames_read);
  });
}

}  // namespace resolver::bench_live
