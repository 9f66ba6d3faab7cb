// CandumpReader: a candump -l log file as a stream of CanFrames.
//
// Reads the file in large chunks with read(2) into one reused buffer and
// parses each line in place (parse_candump_line), so the good path makes no
// allocation per line. Works on regular files, FIFOs and /dev/stdin.
//
// Bad input never throws: next() returns kBadLine, problem() says why, and the
// next call continues with the following line, so callers can count problems
// by to_string(problem().kind). Only I/O failures throw (std::runtime_error).
// Not thread-safe; one reader per thread.
//
// Stopping: with set_stop_flag(), every read checks the flag, and input that
// is not a regular file (a FIFO with no writer, a device, a terminal) is
// polled with a kStopPollMs timeout first, so a set flag ends next() (kEnd,
// stopped() true) within that time on any input: an endless line (/dev/zero)
// is checked once per buffer, a silent FIFO once per timeout. Opening never
// blocks (a FIFO without a writer is waited for in the first read).
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>

#include "drivers/can_frame.h"
#include "drivers/candump/candump_line.h"

namespace resolver {

class CandumpReader {
 public:
  /// [bytes] read(2) chunk. 1 MiB amortises the syscall over ~30 k lines and
  /// stays in L2/L3; much larger buys nothing measurable.
  static constexpr std::size_t kDefaultBufferBytes = std::size_t{1} << 20;
  /// [bytes] smallest buffer: a longest accepted line plus room for a whole
  /// next read, so a refill never finds the buffer full.
  static constexpr std::size_t kMinBufferBytes = 2 * (kMaxCandumpLineLength + 1);
  /// [ms] longest wait for input between two looks at the stop flag.
  static constexpr int kStopPollMs = 100;

  /// Opens `path`. Throws std::runtime_error("cannot open <path>: <strerror>").
  /// `buffer_bytes` is raised to kMinBufferBytes; a small buffer only costs
  /// syscalls (the fuzz target uses it so each run does not pay for 1 MiB).
  explicit CandumpReader(const std::string& path, std::size_t buffer_bytes = kDefaultBufferBytes);
  ~CandumpReader();
  CandumpReader(const CandumpReader&) = delete;
  CandumpReader& operator=(const CandumpReader&) = delete;
  CandumpReader(CandumpReader&& other) noexcept;
  CandumpReader& operator=(CandumpReader&& other) noexcept;

  enum class Status { kFrame, kBadLine, kEnd };

  /// kFrame: `frame` holds the next frame. kBadLine: problem() describes the
  /// line (frame contents unspecified). kEnd: no more lines (repeats).
  /// Blank lines are skipped silently. A frame whose timestamp is earlier than
  /// the previous good frame's is kBadLine / kNonMonotonicTimestamp (equal is fine).
  /// Throws std::runtime_error naming the path and strerror if read(2) fails.
  Status next(CanFrame& frame);

  /// The last bad line's problem; valid after next() returned kBadLine.
  [[nodiscard]] const LogLineProblem& problem() const { return problem_; }
  /// 1-based number of the line last returned (blank lines count).
  [[nodiscard]] std::uint64_t line_number() const { return line_number_; }
  /// [bytes] consumed through the end of the line last returned.
  [[nodiscard]] std::uint64_t bytes_read() const { return bytes_consumed_; }
  /// [bytes] file size, 0 if unknown (pipe, FIFO).
  [[nodiscard]] std::uint64_t total_bytes() const { return total_bytes_; }
  [[nodiscard]] const std::string& path() const { return path_; }

  /// From now on, next() returns kEnd soon after `*stop` becomes true (see the file
  /// comment). nullptr: never stop early (the default). The flag must outlive the reader.
  void set_stop_flag(const std::atomic<bool>* stop) { stop_ = stop; }
  /// True when next() ended because the stop flag was set, not at the end of input.
  [[nodiscard]] bool stopped() const { return stopped_; }

 private:
  /// Sets `line` to the next line without its '\n'. Returns false at end of
  /// input. A line longer than the buffer can hold is dropped and reported
  /// through `skipped_len` (its length in bytes) with `line` empty.
  bool take_line(std::string_view& line, std::uint64_t& skipped_len);
  /// Appends up to the free buffer space from the file; sets eof_ on 0, and
  /// eof_ and stopped_ when the stop flag is set.
  void fill();
  /// Waits (kStopPollMs at a time, checking the stop flag) until a read will not
  /// block. False when the flag was set.
  bool wait_readable();
  void close_fd() noexcept;

  std::string path_;
  int fd_ = -1;
  std::size_t buffer_bytes_;
  std::unique_ptr<char[]> buffer_;
  std::size_t begin_ = 0;  // first unconsumed byte in buffer_
  std::size_t end_ = 0;    // one past the last valid byte in buffer_
  bool eof_ = false;
  std::uint64_t line_number_ = 0;
  std::uint64_t bytes_consumed_ = 0;
  std::uint64_t total_bytes_ = 0;
  bool have_previous_ = false;
  std::int64_t previous_timestamp_us_ = 0;  // [us] of the last good frame
  LogLineProblem problem_;
  const std::atomic<bool>* stop_ = nullptr;
  bool stopped_ = false;
  bool poll_before_read_ = false;  // not a regular file: a read may block
};

}  // namespace resolver
