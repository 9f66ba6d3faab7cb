#include "daemon/app/replay_runner.h"

#include <fmt/format.h>
#include <unistd.h>

#include <chrono>
#include <thread>

#include "drivers/candump/candump_line.h"
#include "drivers/candump/candump_reader.h"

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

  while (!flags.stop.load()) {
    CandumpReader reader(options.path);
    ++result.passes;
    if (result.passes > 1) pipeline.restart_sequence();
    CanFrame frame;
    bool have_t0 = false;
    std::int64_t log_t0 = 0;
    Clock::time_point wall_t0;
    while (!flags.stop.load()) {
      const auto status = reader.next(frame);
      if (status == CandumpReader::Status::kEnd) break;
      if (status == CandumpReader::Status::kBadLine) {
        ++result.bad_lines;
        const LogLineProblem& pr = reader.problem();
        pipeline.count_problem(to_string(pr.kind), fmt::format("{}:{}:{}: {}", options.path, reader.line_number(),
                                                                pr.column, pr.message));
        continue;
      }
      if (!options.fast) {
        if (!have_t0) {
          have_t0 = true;
          log_t0 = frame.timestamp_us;
          wall_t0 = Clock::now();
        }
        std::this_thread::sleep_until(wall_t0 + std::chrono::microseconds(frame.timestamp_us - log_t0));
      }
      ++result.frames;
      // Paced replay times every frame, like live input. Fast replay times one
      // frame in kReplayLatencyEvery: the percentiles stay representative and
      // the other frames skip the clock read.
      if (!options.fast || result.frames % kReplayLatencyEvery == 1) {
        pipeline.feed(frame, reader.line_number(), Clock::now());
      } else {
        pipeline.feed_untimed(frame, reader.line_number());
      }
      if (options.progress && (result.frames & 0xFFFU) == 0) {
        const auto now = Clock::now();
        if (now >= next_progress) {
          next_progress = now + kProgressEvery;
          const double s = std::chrono::duration<double>(now - wall_start).count();
          const double pct = reader.total_bytes() > 0
                                 ? 100.0 * static_cast<double>(reader.bytes_read()) / static_cast<double>(reader.total_bytes())
                                 : 0.0;
          err << fmt::format("{}resolverd: {:5.1f}% of {} ({} frames, {:.0f} frames/s){}", tty ? "\r" : "", pct,
                             options.path, result.frames, static_cast<double>(result.frames) / s, tty ? "" : "\n");
          err.flush();
          printed_progress = true;
        }
      }
    }
    if (options.once) break;
  }
  if (printed_progress && tty) err << "\n";
  pipeline.finish();
  result.wall_seconds = std::chrono::duration<double>(Clock::now() - wall_start).count();
  return result;
}

}  // namespace resolver
