#include "daemon/app/replay_runner.h"

#include <fmt/format.h>
#include <unistd.h>

#include <chrono>
#include <thread>

#include "daemon/app/log_input.h"

namespace resolver {

namespace {
using Clock = std::chrono::steady_clock;
constexpr auto kProgressEvery = std::chrono::seconds(2);
}  // namespace

ReplayResult run_replay(const ReplayOptions& options, Pipeline& pipeline, StopFlags& flags, std::ostream& err) {
  ReplayResult result;
  const auto wall_start = Clock::now();
  const bool tty = isatty(STDERR_FILENO) != 0;
  auto next_progress = wall_start + kProgressEvery;
  bool printed_progress = false;

  const LogFormat format = resolve_log_format(options.path, options.format, pipeline.config());
  while (!flags.stop.load()) {
    const std::unique_ptr<LogInput> reader = open_log_input(options.path, format, pipeline.config());
    ++result.passes;
    if (result.passes > 1) pipeline.restart_sequence();
    LogRecord record;
    bool have_t0 = false;
    std::int64_t log_t0 = 0;
    std::int64_t last_us = 0;
    Clock::time_point wall_t0;
    while (!flags.stop.load() && !pipeline.past_slice_end()) {
      const auto status = reader->next(record);
      if (status == LogInput::Status::kEnd) break;
      if (status == LogInput::Status::kBadLine) {
        ++result.bad_lines;
        const TextProblem& pr = reader->problem();
        pipeline.count_problem(pr.reason, fmt::format("{}:{}:{}: {}", options.path, reader->line_number(),
                                                       pr.column, pr.message));
        continue;
      }
      if (!options.fast) {
        const std::int64_t step = record.timestamp_us - last_us;
        if (!have_t0 || step < 0 || step > kMaxPacedGapUs) {
          have_t0 = true;
          log_t0 = record.timestamp_us;
          wall_t0 = Clock::now();
        }
        last_us = record.timestamp_us;
        std::this_thread::sleep_until(wall_t0 + std::chrono::microseconds(record.timestamp_us - log_t0));
      }
      ++result.frames;
      if (record.is_row) {
        pipeline.feed_row(record.row, reader->line_number());
      } else if (!options.fast || result.frames % kReplayLatencyEvery == 1) {
        // Paced replay times every frame, like live input. Fast replay times one
        // frame in kReplayLatencyEvery: the percentiles stay representative and
        // the other frames skip the clock read.
        pipeline.feed(record.frame, reader->line_number(), Clock::now());
      } else {
        pipeline.feed_untimed(record.frame, reader->line_number());
      }
      if (options.progress && (result.frames & 0xFFFU) == 0) {
        const auto now = Clock::now();
        if (now >= next_progress) {
          next_progress = now + kProgressEvery;
          const double s = std::chrono::duration<double>(now - wall_start).count();
          const double pct = reader->total_bytes() > 0
                                 ? 100.0 * static_cast<double>(reader->bytes_read()) / static_cast<double>(reader->total_bytes())
                                 : 0.0;
          err << fmt::format("{}resolverd: {:5.1f}% of {} ({} frames, {:.0f} frames/s){}", tty ? "\r" : "", pct,
                             options.path, result.frames, static_cast<double>(result.frames) / s, tty ? "" : "\n");
          err.flush();
          printed_progress = true;
        }
      }
    }
    if (options.once || pipeline.past_slice_end()) break;
  }
  if (printed_progress && tty) err << "\n";
  pipeline.finish();
  result.wall_seconds = std::chrono::duration<double>(Clock::now() - wall_start).count();
  return result;
}

}  // namespace resolver
