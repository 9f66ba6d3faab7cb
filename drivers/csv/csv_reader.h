// CsvReader: a CSV or scope export as a stream of rows of text fields.
//
// Skips the lines before the data (CsvFormat::header_lines, or until a line of
// numbers), reads the column-name line when there is one, finds the separator
// when asked to (CsvFormat::Delimiter::kAuto, decided once on the first data
// line) and splits each data line into fields, trimmed of spaces and of
// surrounding double quotes. It does not parse numbers or know what a column
// means (daemon/decode/row_decoder.h does). Blank lines and a UTF-8 byte order
// mark are skipped. Only I/O failures throw. Not thread-safe.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "drivers/csv/csv_format.h"
#include "drivers/text/line_reader.h"
#include "drivers/text/text_problem.h"

namespace resolver {

/// One data line split into fields; views into the reader's buffer, valid until the next call.
struct CsvRow {
  std::vector<std::string_view> fields;
  std::vector<std::size_t> columns;  ///< 1-based byte column where each field starts
  std::size_t end_column = 1;        ///< one past the line's last byte (for "missing field" messages)
};

/// Splits `line` at `delimiter` (not kAuto) into `row`. Cannot fail.
void split_csv_line(std::string_view line, CsvFormat::Delimiter delimiter, CsvRow& row);
/// The separator a data line uses, for Delimiter::kAuto (see CsvFormat).
[[nodiscard]] CsvFormat::Delimiter detect_csv_delimiter(std::string_view line, char decimal);

class CsvReader {
 public:
  /// Longest line [bytes]: a scope export with hundreds of channels still fits.
  static constexpr std::size_t kMaxLineLength = 65536;

  /// Opens `path`. Throws std::runtime_error("cannot open <path>: <strerror>").
  CsvReader(const std::string& path, const CsvFormat& format,
            std::size_t buffer_bytes = LineReader::kDefaultBufferBytes);

  enum class Status { kRow, kBadLine, kEnd };
  /// kRow: `row` holds the next data line's fields. kBadLine: problem() says
  /// why (a line too long). Throws std::runtime_error if read(2) fails.
  Status next(CsvRow& row);

  /// The column-name line's fields (empty without one); complete once next()
  /// has returned the first row or kEnd.
  [[nodiscard]] const std::vector<std::string>& column_names() const { return names_; }
  /// Line number of the column names (0 = none).
  [[nodiscard]] std::uint64_t names_line() const { return names_line_; }
  [[nodiscard]] CsvFormat::Delimiter delimiter() const { return delimiter_; }
  [[nodiscard]] const TextProblem& problem() const { return problem_; }
  [[nodiscard]] std::uint64_t line_number() const { return lines_.line_number(); }
  [[nodiscard]] std::uint64_t bytes_read() const { return lines_.bytes_read(); }
  [[nodiscard]] std::uint64_t total_bytes() const { return lines_.total_bytes(); }
  /// next() ends soon after `*stop` becomes true, on any input (line_reader.h).
  void set_stop_flag(const std::atomic<bool>* stop) { lines_.set_stop_flag(stop); }
  [[nodiscard]] bool stopped() const { return lines_.stopped(); }

 private:
  /// Before the data: true when `line` is a header line (skipped or names).
  bool take_header_line(std::string_view line);
  void set_names(std::string_view line);

  LineReader lines_;
  CsvFormat format_;
  CsvFormat::Delimiter delimiter_;
  bool in_data_ = false;
  int skipped_ = 0;
  std::string last_skipped_;  ///< skip_until_numbers: the candidate name line
  std::vector<std::string> names_;
  std::uint64_t names_line_ = 0;
  std::uint64_t last_skipped_line_ = 0;
  TextProblem problem_;
  CsvRow scratch_;
};

}  // namespace resolver
