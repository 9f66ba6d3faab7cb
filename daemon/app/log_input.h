// One replayed log file, whatever its format, as a stream of frames or rows:
// the dispatch from file format to reader that resolverd --replay and
// resolver-model share (so both read every format the same way).
//
//   candump -l  (.log)       CandumpReader  -> CanFrame
//   Vector ASC  (.asc)       AscReader      -> CanFrame
//   CSV / scope (.csv, .txt) CsvReader + RowDecoder ([input.csv]) -> RowSample
//
// The format comes from --format, else [input] format, else the extension.
// A bad line or row is a kBadLine with a problem naming the column; never fatal.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "daemon/app/daemon_config.h"
#include "daemon/decode/row_sample.h"
#include "drivers/can_frame.h"
#include "drivers/text/text_problem.h"

namespace resolver {

struct LogRecord {
  bool is_row = false;  ///< a CSV row (row), else a CAN frame (frame)
  CanFrame frame;
  RowSample row;
  /// [us] when it happened in the log's time (paced replay).
  std::int64_t timestamp_us = 0;
};

class LogInput {
 public:
  enum class Status { kRecord, kBadLine, kEnd };
  virtual ~LogInput() = default;
  /// The next frame or row. Throws std::system_error on an I/O failure.
  virtual Status next(LogRecord& record) = 0;
  /// Valid after kBadLine: counter name, 1-based column, message.
  [[nodiscard]] virtual const TextProblem& problem() const = 0;
  [[nodiscard]] virtual std::uint64_t line_number() const = 0;
  [[nodiscard]] virtual std::uint64_t bytes_read() const = 0;
  [[nodiscard]] virtual std::uint64_t total_bytes() const = 0;
  /// next() returns kEnd soon after `*stop` becomes true, on any input (line_reader.h).
  virtual void set_stop_flag(const std::atomic<bool>* stop) = 0;
  /// True when next() ended because of the stop flag.
  [[nodiscard]] virtual bool stopped() const = 0;
  [[nodiscard]] LogFormat format() const { return format_; }

 protected:
  explicit LogInput(LogFormat format) : format_(format) {}

 private:
  LogFormat format_;
};

/// The format to read `path` with: `forced` (--format), else the config's
/// [input] format, else the extension.
[[nodiscard]] LogFormat resolve_log_format(const std::string& path, std::optional<LogFormat> forced,
                                           const DaemonConfig& config);

/// Throws ConfigError, naming the file and the command that converts it, when
/// `path` is a format no reader here takes but a text reader would misread line by
/// line: Vector BLF (extension .blf, or the magic "LOGG") and gzip (.gz, or the
/// magic 1f 8b). The content is looked at only in a regular file.
void refuse_unreadable_format(const std::string& path);

/// Opens `path`. Throws std::system_error when it cannot be opened, and
/// ConfigError when a CSV has no column map or names a column the export lacks,
/// or the file is BLF or gzip (refuse_unreadable_format).
[[nodiscard]] std::unique_ptr<LogInput> open_log_input(const std::string& path, LogFormat format,
                                                       const DaemonConfig& config);

}  // namespace resolver
