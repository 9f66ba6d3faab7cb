// CandumpWriter: CanFrames -> a candump -l log file that canplayer, log2asc
// and python-can read.
//
// Lines are formatted into one reused buffer and written with write(2) in
// 64 KiB chunks, so the good path makes no allocation per frame. Every
// failure throws (the caller decides whether a lost log is fatal).
#pragma once

#include <cstdint>
#include <string>

#include "daemon/core/errors.h"
#include "drivers/can_frame.h"

namespace resolver {

class CandumpWriter {
 public:
  /// Creates or truncates `path` (mode 0644). Throws std::system_error
  /// ("cannot create <path>: <strerror>").
  explicit CandumpWriter(const std::string& path);
  /// Closes without throwing; a failure here is lost, so call close() to see it.
  ~CandumpWriter();
  CandumpWriter(const CandumpWriter&) = delete;
  CandumpWriter& operator=(const CandumpWriter&) = delete;

  /// Appends one line. Throws InputError (check_loggable(): "PATH:LINE: cannot log
  /// this frame: WHY"; nothing is written), std::system_error on an I/O error or
  /// after close().
  void write(const CanFrame& frame);
  /// Flushes and closes; throws std::system_error naming the path and strerror.
  /// A second call does nothing.
  void close();
  [[nodiscard]] std::uint64_t frames_written() const { return frames_written_; }
  [[nodiscard]] const std::string& path() const { return path_; }

 private:
  void flush();

  std::string path_;
  Where line_at_;  ///< path_ and the next line, for check_loggable (no allocation per frame)
  int fd_ = -1;
  std::string buffer_;
  std::uint64_t frames_written_ = 0;
};

}  // namespace resolver
