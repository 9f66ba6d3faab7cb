// LineReader: a text file (regular file, FIFO, /dev/stdin) as a stream of lines,
// the I/O half of every log reader (candump, Vector ASC, CSV).
//
// Reads in large chunks with read(2) into one reused buffer and hands out each
// line in place as a string_view (valid until the next call), so the good path
// makes no allocation per line. A line longer than the limit is skipped to its
// end and reported, so one corrupt stretch (a binary file read by mistake)
// cannot make the buffer grow. Only I/O failures throw (std::system_error
// naming the path and strerror). Not thread-safe; one reader per thread.
//
// Stopping: with set_stop_flag(), every read checks the flag, and input that is
// not a regular file (a FIFO with no writer, a device, a terminal) is polled with
// a kStopPollMs timeout first, so a set flag ends next() (kEnd, stopped() true)
// within that time on any input: an endless line (/dev/zero) is checked once per
// buffer, a silent FIFO once per timeout. Opening never blocks (a FIFO without a
// writer is waited for in the first read).
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>

#include "drivers/text/text_problem.h"

namespace resolver {

class LineReader {
 public:
  /// [bytes] read(2) chunk. 1 MiB amortises the syscall over ~30 k candump
  /// lines and stays in L2/L3; much larger buys nothing measurable.
  static constexpr std::size_t kDefaultBufferBytes = std::size_t{1} << 20;
  /// [ms] longest wait for input between two looks at the stop flag.
  static constexpr int kStopPollMs = 100;

  /// Opens `path`. Throws std::system_error("cannot open <path>: <strerror>").
  /// `buffer_bytes` is raised to min_buffer_bytes(max_line_length).
  LineReader(const std::string& path, std::size_t max_line_length, std::size_t buffer_bytes = kDefaultBufferBytes);
  ~LineReader();
  LineReader(const LineReader&) = delete;
  LineReader& operator=(const LineReader&) = delete;
  LineReader(LineReader&& other) noexcept;
  LineReader& operator=(LineReader&& other) noexcept;

  /// [bytes] smallest buffer for a line limit: a longest line plus room for a
  /// whole next read, so a refill never finds the buffer full.
  static constexpr std::size_t min_buffer_bytes(std::size_t max_line_length) { return 2 * (max_line_length + 1); }

  enum class Result { kLine, kTooLong, kEnd };
  /// kLine: `line` is the next line without its '\n' (the last line may lack
  /// one). kTooLong: a line of more than max_line_length bytes was skipped;
  /// skipped_length() says how long it was. kEnd: no more lines (repeats).
  /// Throws std::system_error naming the path and strerror if read(2) fails.
  Result next(std::string_view& line);

  /// 1-based number of the line last returned.
  [[nodiscard]] std::uint64_t line_number() const { return line_number_; }
  /// [bytes] length of the line kTooLong skipped.
  [[nodiscard]] std::uint64_t skipped_length() const { return skipped_len_; }
  /// The problem to report for the line kTooLong skipped ("line_too_long",
  /// column one past the limit); `expected` names the format, e.g. "a Vector ASC log".
  [[nodiscard]] TextProblem too_long_problem(std::string_view expected) const;
  /// [bytes] consumed through the end of the line last returned.
  [[nodiscard]] std::uint64_t bytes_read() const { return bytes_consumed_; }
  /// [bytes] file size, 0 if unknown (pipe, FIFO).
  [[nodiscard]] std::uint64_t total_bytes() const { return total_bytes_; }
  [[nodiscard]] const std::string& path() const { return path_; }
  [[nodiscard]] std::size_t max_line_length() const { return max_line_; }

  /// From now on, next() returns kEnd soon after `*stop` becomes true (see the file
  /// comment). nullptr: never stop early (the default). The flag must outlive the reader.
  void set_stop_flag(const std::atomic<bool>* stop) { stop_ = stop; }
  /// True when next() ended because the stop flag was set, not at the end of input.
  [[nodiscard]] bool stopped() const { return stopped_; }

 private:
  /// Appends up to the free buffer space from the file; sets eof_ on 0, and eof_
  /// and stopped_ when the stop flag is set.
  void fill();
  /// Waits (kStopPollMs at a time, checking the stop flag) until a read will not
  /// block. False when the flag was set.
  bool wait_readable();
  void close_fd() noexcept;

  std::string path_;
  int fd_ = -1;
  std::size_t max_line_;
  std::size_t buffer_bytes_;
  std::unique_ptr<char[]> buffer_;
  std::size_t begin_ = 0;  // first unconsumed byte in buffer_
  std::size_t end_ = 0;    // one past the last valid byte in buffer_
  bool eof_ = false;
  std::uint64_t line_number_ = 0;
  std::uint64_t skipped_len_ = 0;
  std::uint64_t bytes_consumed_ = 0;
  std::uint64_t total_bytes_ = 0;
  const std::atomic<bool>* stop_ = nullptr;
  bool stopped_ = false;
  bool poll_before_read_ = false;  ///< not a regular file: a read may block
};

/// True for a line of only spaces, tabs and '\r'.
[[nodiscard]] bool is_blank_line(std::string_view line);

}  // namespace resolver
