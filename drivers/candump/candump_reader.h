// CandumpReader: a candump -l log file as a stream of CanFrames.
//
// Reads lines with a LineReader (drivers/text/line_reader.h: large read(2)
// chunks, lines in place) and parses each with parse_candump_line, so the good
// path makes no allocation per line. Works on regular files, FIFOs and /dev/stdin.
//
// Bad input never throws: next() returns kBadLine, problem() says why, and the
// next call continues with the following line, so callers can count problems
// by to_string(problem().kind). Only I/O failures throw (std::system_error).
// Timestamps are passed on as they are, also when they step back or jump:
// what time means is the sample clock's business (daemon/decode/sample_clock.h),
// and a step is no reason to lose the frames after it.
// Not thread-safe; one reader per thread.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>

#include "drivers/can_frame.h"
#include "drivers/candump/candump_line.h"
#include "drivers/text/line_reader.h"

namespace resolver {

class CandumpReader {
 public:
  /// [bytes] read(2) chunk. 1 MiB amortises the syscall over ~30 k lines and
  /// stays in L2/L3; much larger buys nothing measurable.
  static constexpr std::size_t kDefaultBufferBytes = LineReader::kDefaultBufferBytes;
  /// [bytes] smallest buffer: a longest accepted line plus room for a whole
  /// next read, so a refill never finds the buffer full.
  static constexpr std::size_t kMinBufferBytes = LineReader::min_buffer_bytes(kMaxCandumpLineLength);

  /// Opens `path`. Throws std::system_error("cannot open <path>: <strerror>").
  /// `buffer_bytes` is raised to kMinBufferBytes; a small buffer only costs
  /// syscalls (the fuzz target uses it so each run does not pay for 1 MiB).
  explicit CandumpReader(const std::string& path, std::size_t buffer_bytes = kDefaultBufferBytes)
      : lines_(path, kMaxCandumpLineLength, buffer_bytes) {}

  enum class Status { kFrame, kBadLine, kEnd };

  /// kFrame: `frame` holds the next frame. kBadLine: problem() describes the
  /// line (frame contents unspecified). kEnd: no more lines (repeats).
  /// Blank lines are skipped silently.
  /// Throws std::system_error naming the path and strerror if read(2) fails.
  Status next(CanFrame& frame);

  /// The last bad line's problem; valid after next() returned kBadLine.
  [[nodiscard]] const LogLineProblem& problem() const { return problem_; }
  /// 1-based number of the line last returned (blank lines count).
  [[nodiscard]] std::uint64_t line_number() const { return lines_.line_number(); }
  /// [bytes] consumed through the end of the line last returned.
  [[nodiscard]] std::uint64_t bytes_read() const { return lines_.bytes_read(); }
  /// [bytes] file size, 0 if unknown (pipe, FIFO).
  [[nodiscard]] std::uint64_t total_bytes() const { return lines_.total_bytes(); }
  [[nodiscard]] const std::string& path() const { return lines_.path(); }
  /// From now on, next() returns kEnd soon after `*stop` becomes true (line_reader.h).
  void set_stop_flag(const std::atomic<bool>* stop) { lines_.set_stop_flag(stop); }
  /// True when next() ended because the stop flag was set, not at the end of input.
  [[nodiscard]] bool stopped() const { return lines_.stopped(); }

 private:
  LineReader lines_;
  LogLineProblem problem_;
};

}  // namespace resolver
