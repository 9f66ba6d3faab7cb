#include "daemon/app/replay_runner.h"

#include <fmt/format.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <optional>
#include <thread>

#include "daemon/app/log_input.h"
#include "daemon/app/progress_meter.h"
#include "daemon/core/errors.h"

namespace resolver {

namespace {
using Clock = std::chrono::steady_clock;
constexpr auto kProgressEvery = std::chrono::seconds(2);
/// Longest uninterrupted sleep of paced replay: SIGTERM is seen within this.
constexpr auto kSleepSlice = std::chrono::milliseconds(50);
/// [us] gap between two passes of a loop when the log has one frame.
constexpr std::int64_t kDefaultLoopGapUs = 1000;

/// Sleeps until `until` in slices; false when a stop or reload request came first.
bool sleep_until_or_signal(Clock::time_point until, const StopFlags& flags) {
  for (;;) {
    if (flags.stop.load(std::memory_order_relaxed) || flags.reload.load(std::memory_order_relaxed)) return false;
    const auto now = Clock::now();
    if (now >= until) return true;
    std::this_thread::sleep_for(std::min<Clock::duration>(until - now, kSleepSlice));
  }
}

/// Paced replay's clock: the log's time from its anchor, at `rate`.
struct Pacing {
  bool anchored = false;
  std::int64_t log_t0 = 0, last_us = 0;
  Clock::time_point wall_t0;
};

/// Waits until `stamp_us` is due; serves reload requests meanwhile. False: stop requested.
bool wait_for(std::int64_t stamp_us, double rate, Pacing& pacing, StopFlags& flags,
              const std::function<void()>& on_reload) {
  // A stamp that steps back or jumps far re-anchors the pacing (it is no
  // reason to wait a day); the sample clock deals with what time means.
  const std::int64_t step = stamp_us - pacing.last_us;
  if (!pacing.anchored || step < 0 || step > kMaxPacedGapUs) {
    pacing.anchored = true;
    pacing.log_t0 = stamp_us;
    pacing.wall_t0 = Clock::now();
  }
  pacing.last_us = stamp_us;
  const auto due = pacing.wall_t0 + std::chrono::microseconds(static_cast<std::int64_t>(
                                        static_cast<double>(stamp_us - pacing.log_t0) / rate));
  // A reload request interrupts the wait; it is served before the next frame.
  while (!sleep_until_or_signal(due, flags) && !flags.stop.load()) {
    if (flags.reload.exchange(false)) on_reload();
  }
  return !flags.stop.load();
}

/// One frame or row into the pipeline, shifted by the loop's offset.
void feed_record(LogRecord& record, Pipeline& target, std::int64_t line, std::int64_t offset_us, bool fast,
                 std::int64_t frames) {
  if (record.is_row) {
    if (record.row.has_time) record.row.time_us += offset_us;
    target.feed_row(record.row, line);
    return;
  }
  record.frame.timestamp_us += offset_us;
  // Paced replay times every frame, like live input. Fast replay times one
  // frame in kReplayLatencyEvery: the percentiles stay representative and
  // the other frames skip the clock read.
  if (!fast || frames % kReplayLatencyEvery == 1) {
    target.feed(record.frame, line, Clock::now());
  } else {
    target.feed_untimed(record.frame, line);
  }
}

/// Not on a terminal (a journal, a pipe): one progress line every kProgressEvery.
void progress_line(const ReplayOptions& options, const LogInput& reader, std::int64_t frames,
                   Clock::time_point wall_start, Clock::time_point& next_progress, std::ostream& err) {
  const auto now = Clock::now();
  if (now < next_progress) return;
  next_progress = now + kProgressEvery;
  const double s = std::chrono::duration<double>(now - wall_start).count();
  const double pct = reader.total_bytes() > 0
                         ? 100.0 * static_cast<double>(reader.bytes_read()) / static_cast<double>(reader.total_bytes())
                         : 0.0;
  err << fmt::format("resolverd: {:5.1f}% of {} ({} frames, {:.0f} frames/s)\n", pct, options.path, frames,
                     static_cast<double>(frames) / s);
  err.flush();
}

/// A regular file read to its end gave the bytes it had when opened; fewer: it was
/// truncated or replaced meanwhile (an I/O error), more: a log still being written.
void check_size_after_pass(const ReplayOptions& options, const LogInput& reader, bool at_end, std::ostream& err) {
  const std::uint64_t at_open = reader.total_bytes();
  if (!at_end || at_open == 0) return;
  if (reader.bytes_read() < at_open) {
    throw IoError(fmt::format("{}: the file shrank while it was replayed: {} bytes when opened, its end came after {} "
                              "(truncated, or replaced by another file?); replay a copy that nothing writes to",
                              options.path, at_open, reader.bytes_read()));
  }
  if (reader.bytes_read() > at_open) {
    err << fmt::format("resolverd: {} grew while it was replayed ({} bytes when opened, {} read to the end): a log "
                       "still being written; this pass ended at the end it met\n",
                       options.path, at_open, reader.bytes_read());
  }
}

/// Whether a loop can read the file again after a pass of `pass_frames` frames; says why not.
bool can_loop(const ReplayOptions& options, bool regular, std::int64_t pass_frames, std::ostream& err) {
  if (!regular) {
    err << "resolverd: " << options.path << " is not a regular file (a FIFO, pipe or device): it is read once, "
        << "there is nothing to replay again; stopping after one pass (--once says so; to loop, replay a file)\n";
    return false;
  }
  if (pass_frames == 0) {
    // Nothing to loop over: an empty (or all-bad) log would spin here forever.
    err << "resolverd: " << options.path << " has no frames to loop over; stopping after one pass\n";
    return false;
  }
  return true;
}
}  // namespace

ReplayResult run_replay(const ReplayOptions& options, Pipeline& pipeline, StopFlags& flags, std::ostream& err) {
  return run_replay(options, [&pipeline]() -> Pipeline& { return pipeline; }, [] {}, flags, err);
}

ReplayResult run_replay(const ReplayOptions& options, const std::function<Pipeline&()>& current,
                        const std::function<void()>& on_reload, StopFlags& flags, std::ostream& err) {
  ReplayResult result;
  const auto wall_start = Clock::now();
  // On a terminal: one line rewritten at most 4 times a second (bytes, frames, rate,
  // ETA), erased at the end. Elsewhere (a journal, a pipe): a line every 2 s.
  const bool tty = isatty(STDERR_FILENO) != 0;
  ProgressMeter::Options meter_options;
  meter_options.enabled = options.progress && tty;
  std::optional<ProgressMeter> meter;
  auto next_progress = wall_start + kProgressEvery;
  const double rate = options.rate > 0.0 ? options.rate : 1.0;
  // Loop passes: pass k's frame times are shifted by k * loop_span_us.
  std::int64_t loop_span_us = 0;
  std::int64_t offset_us = 0;

  const LogFormat format = resolve_log_format(options.path, options.format, current().config());
  // A FIFO, pipe or device is read once: what was read from it is gone, so a loop
  // has nothing to read again (a reopened pipe is at its end, a FIFO waits for
  // another writer's unrelated data).
  struct stat st {};
  const bool regular = ::stat(options.path.c_str(), &st) == 0 && S_ISREG(st.st_mode);
  while (!flags.stop.load()) {
    const std::unique_ptr<LogInput> reader = open_log_input(options.path, format, current().config());
    reader->set_stop_flag(&flags.stop);
    ++result.passes;
    if (meter_options.enabled) {
      meter.reset();
      meter.emplace(stderr, result.passes > 1 ? fmt::format("resolverd: {} (pass {})", options.path, result.passes)
                                              : "resolverd: " + options.path,
                    meter_options);
      meter->set_items_word("frames");
    }
    if (result.passes > 1) {
      current().restart_sequence();
      offset_us += loop_span_us;
    }
    LogRecord record;
    Pacing pacing;
    std::int64_t first_us = 0, max_us = 0, pass_frames = 0;
    bool at_end = false;  // the end of the file, not of --to or a stop
    while (!flags.stop.load() && !current().past_slice_end()) {
      if (flags.reload.load(std::memory_order_relaxed) && flags.reload.exchange(false)) on_reload();
      const auto status = reader->next(record);
      if (status == LogInput::Status::kEnd) {
        at_end = !reader->stopped();
        break;
      }
      Pipeline& pipeline = current();
      if (status == LogInput::Status::kBadLine) {
        ++result.bad_lines;
        const TextProblem& pr = reader->problem();
        pipeline.count_problem(pr.reason, fmt::format("{}:{}:{}: {}", options.path, reader->line_number(),
                                                       pr.column, pr.message));
        continue;
      }
      if (pass_frames++ == 0) first_us = max_us = record.timestamp_us;
      max_us = std::max(max_us, record.timestamp_us);
      if (!options.fast && !wait_for(record.timestamp_us, rate, pacing, flags, on_reload)) break;
      ++result.frames;
      feed_record(record, current(), reader->line_number(), offset_us, options.fast, result.frames);
      if ((result.frames & 0xFFFU) != 0) continue;
      if (meter) {
        meter->bytes(reader->bytes_read(), reader->total_bytes(), static_cast<std::int64_t>(result.frames));
      } else if (options.progress && !tty) {
        progress_line(options, *reader, result.frames, wall_start, next_progress, err);
      }
    }
    if (meter) meter->finish();
    check_size_after_pass(options, *reader, at_end, err);
    if (options.once || reader->stopped() || current().past_slice_end()) break;
    if (!can_loop(options, regular, pass_frames, err)) break;
    if (loop_span_us == 0) {
      const std::int64_t interval = pass_frames > 1 ? (max_us - first_us) / (pass_frames - 1) : kDefaultLoopGapUs;
      loop_span_us = max_us - first_us + std::max<std::int64_t>(interval, 1);
    }
  }
  current().finish();
  result.wall_seconds = std::chrono::duration<double>(Clock::now() - wall_start).count();
  return result;
}

}  // namespace resolver
