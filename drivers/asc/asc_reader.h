// AscReader: a Vector ASC log file as a stream of CanFrames, in the shape of
// CandumpReader: next() returns kFrame, kBadLine (problem() says why, with a
// column) or kEnd; headers, comments and "Start of measurement" are skipped
// silently. Only I/O failures throw. Not thread-safe.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "drivers/asc/asc_line.h"
#include "drivers/text/line_reader.h"

namespace resolver {

class AscReader {
 public:
  /// Longest line [bytes] accepted: a CAN FD line with 64 data bytes and every
  /// trailing field is ~400 bytes.
  static constexpr std::size_t kMaxLineLength = 4096;

  /// Opens `path`. Throws std::system_error("cannot open <path>: <strerror>").
  explicit AscReader(const std::string& path, std::size_t buffer_bytes = LineReader::kDefaultBufferBytes)
      : lines_(path, kMaxLineLength, buffer_bytes) {}

  enum class Status { kFrame, kBadLine, kEnd };
  /// Throws std::system_error naming the path and strerror if read(2) fails.
  Status next(CanFrame& frame);

  [[nodiscard]] const TextProblem& problem() const { return problem_; }
  [[nodiscard]] std::uint64_t line_number() const { return lines_.line_number(); }
  [[nodiscard]] std::uint64_t bytes_read() const { return lines_.bytes_read(); }
  [[nodiscard]] std::uint64_t total_bytes() const { return lines_.total_bytes(); }
  /// next() ends soon after `*stop` becomes true, on any input (line_reader.h).
  void set_stop_flag(const std::atomic<bool>* stop) { lines_.set_stop_flag(stop); }
  [[nodiscard]] bool stopped() const { return lines_.stopped(); }
  [[nodiscard]] const AscLineParser& parser() const { return parser_; }

 private:
  LineReader lines_;
  AscLineParser parser_;
  TextProblem problem_;
};

}  // namespace resolver
