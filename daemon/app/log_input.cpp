#include "daemon/app/log_input.h"

#include <sys/stat.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <utility>

#include "daemon/decode/row_decoder.h"
#include "drivers/asc/asc_reader.h"
#include "drivers/candump/candump_reader.h"
#include "drivers/csv/csv_reader.h"

namespace resolver {

namespace {

/// The position accessors every reader has, forwarded.
template <typename Reader>
class ReaderInput : public LogInput {
 public:
  [[nodiscard]] std::uint64_t line_number() const override { return reader_.line_number(); }
  [[nodiscard]] std::uint64_t bytes_read() const override { return reader_.bytes_read(); }
  [[nodiscard]] std::uint64_t total_bytes() const override { return reader_.total_bytes(); }
  void set_stop_flag(const std::atomic<bool>* stop) override { reader_.set_stop_flag(stop); }
  [[nodiscard]] bool stopped() const override { return reader_.stopped(); }
  [[nodiscard]] const TextProblem& problem() const override { return problem_; }

 protected:
  template <typename... Args>
  explicit ReaderInput(LogFormat format, Args&&... args) : LogInput(format), reader_(std::forward<Args>(args)...) {}
  Reader reader_;
  TextProblem problem_;
};

class CandumpInput final : public ReaderInput<CandumpReader> {
 public:
  explicit CandumpInput(const std::string& path) : ReaderInput(LogFormat::kCandump, path) {}
  Status next(LogRecord& record) override {
    record.is_row = false;
    const CandumpReader::Status st = reader_.next(record.frame);
    if (st == CandumpReader::Status::kEnd) return Status::kEnd;
    if (st == CandumpReader::Status::kBadLine) {
      const LogLineProblem& p = reader_.problem();
      problem_ = TextProblem{std::string(to_string(p.kind)), p.column, p.message};
      return Status::kBadLine;
    }
    record.timestamp_us = record.frame.timestamp_us;
    return Status::kRecord;
  }
};

class AscInput final : public ReaderInput<AscReader> {
 public:
  explicit AscInput(const std::string& path) : ReaderInput(LogFormat::kAsc, path) {}
  Status next(LogRecord& record) override {
    record.is_row = false;
    const AscReader::Status st = reader_.next(record.frame);
    if (st == AscReader::Status::kEnd) return Status::kEnd;
    if (st == AscReader::Status::kBadLine) {
      problem_ = reader_.problem();
      return Status::kBadLine;
    }
    record.timestamp_us = record.frame.timestamp_us;
    return Status::kRecord;
  }
};

class CsvInput final : public ReaderInput<CsvReader> {
 public:
  CsvInput(const std::string& path, const CsvInputConfig& config)
      : ReaderInput(LogFormat::kCsv, path, config.format), path_(path), decoder_(config.map), decimal_(config.format.decimal),
        row_rate_hz_(config.map.row_rate_hz) {
    // Read up to the first row so the column names are known and bound now:
    // a column the export lacks is a config error before anything runs.
    first_ = reader_.next(row_);
    decoder_.bind(reader_.column_names(), Where::at_file(path, reader_.names_line()));
    // The first row decides whether the columns line up at all: a first row
    // with more fields than the names (decimal commas split at a ',') would be
    // read, row after row, as other numbers. Refused before anything runs.
    if (first_ == CsvReader::Status::kRow) {
      first_line_ = reader_.line_number();
      first_problem_ = decoder_.decode(row_, decimal_, first_row_, reader_.delimiter());
      if (first_problem_ && first_problem_->reason == "extra_fields") {
        throw ConfigError(path + ":" + std::to_string(reader_.line_number()) + ":" +
                          std::to_string(first_problem_->column) + ": the first data row does not match [input.csv]: " +
                          first_problem_->message);
      }
    }
  }
  Status next(LogRecord& record) override {
    record.is_row = true;
    CsvReader::Status st = CsvReader::Status::kEnd;
    const bool decoded = first_ == CsvReader::Status::kRow;
    if (first_) {
      st = *first_;
      first_.reset();
    } else {
      st = reader_.next(row_);
    }
    if (st == CsvReader::Status::kEnd) {
      check_time_resolution(true);
      return Status::kEnd;
    }
    if (st == CsvReader::Status::kBadLine) {
      problem_ = reader_.problem();
      return Status::kBadLine;
    }
    std::optional<TextProblem> p;
    if (decoded) {
      record.row = first_row_;
      p = std::move(first_problem_);
      first_problem_.reset();
    } else {
      p = decoder_.decode(row_, decimal_, record.row, reader_.delimiter());
    }
    if (p) {
      problem_ = std::move(*p);
      return Status::kBadLine;
    }
    check_time_resolution(false);
    record.timestamp_us =
        record.row.has_time ? record.row.time_us
                            : std::llround(static_cast<double>(record.row.sequence) * 1e6 / row_rate_hz_);
    return Status::kRecord;
  }

 private:
  std::string path_;
  RowDecoder decoder_;
  char decimal_;
  double row_rate_hz_;
  CsvRow row_;
  std::optional<CsvReader::Status> first_;
  /// A time column coarser than the rows (0.01 s at 1 kHz) times no row: refused (InputError).
  void check_time_resolution(bool at_end) {
    decoder_.check_time_resolution(at_end, path_, first_line_, reader_.line_number());
  }

  std::uint64_t first_line_ = 0;             ///< line of the first data row
  RowSample first_row_;                       ///< the first row, decoded in the constructor
  std::optional<TextProblem> first_problem_;  ///< and its problem
};

/// The extension of `path`, lower case, without the dot ("" when none).
std::string extension(const std::string& path) {
  const auto dot = path.rfind('.');
  const auto slash = path.rfind('/');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return "";
  std::string ext = path.substr(dot + 1);
  for (char& ch : ext) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
  return ext;
}

/// The first bytes of a regular file ("" for a FIFO or device: reading would take
/// them from the reader that follows, or block).
std::string leading_bytes(const std::string& path, std::size_t n) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0 || !S_ISREG(st.st_mode)) return "";
  std::ifstream in(path, std::ios::binary);
  std::string bytes(n, '\0');
  in.read(bytes.data(), static_cast<std::streamsize>(n));
  bytes.resize(static_cast<std::size_t>(std::max<std::streamsize>(in.gcount(), 0)));
  return bytes;
}

/// `path` with its extension replaced by `ext` (or `ext` appended).
std::string with_extension(const std::string& path, const std::string& ext) {
  const std::string old = extension(path);
  return (old.empty() ? path : path.substr(0, path.size() - old.size() - 1)) + "." + ext;
}

}  // namespace

void refuse_unreadable_format(const std::string& path) {
  const std::string ext = extension(path);
  const std::string head = leading_bytes(path, 8);
  // BLF: "LOGG" and the file header's size as a little-endian u32 (144 in python-can's
  // and Vector's files), so its two high bytes are 0: no text file starts like that.
  const bool blf_magic = head.size() == 8 && head.rfind("LOGG", 0) == 0 && head[6] == '\0' && head[7] == '\0';
  // gzip: 1f 8b and the method, 08 = deflate (RFC 1952).
  const bool gzip_magic = head.rfind("\x1f\x8b\x08", 0) == 0;
  if (ext == "blf" || blf_magic) {
    const std::string asc = with_extension(path, "asc");
    throw ConfigError(path + " is a Vector BLF (binary logging format) file" +
                      (ext == "blf" ? "" : " (it starts with 'LOGG')") +
                      ", which is not read here (candump, Vector ASC and CSV are); convert it to ASC with python-can "
                      "(Debian: apt install python3-can) and give that: python3 -c \"import can; w=can.ASCWriter('" +
                      asc + "'); [w.on_message_received(m) for m in can.BLFReader('" + path + "')]; w.stop()\"");
  }
  if (ext == "gz" || gzip_magic) {
    // x.log.gz -> x.log; a compressed file without .gz keeps its extension (and so its format).
    const std::string plain = ext == "gz"   ? path.substr(0, path.size() - 3)
                              : ext.empty() ? path + ".log"
                                            : with_extension(path, "unzipped." + ext);
    throw ConfigError(path + " is gzip-compressed" + (ext == "gz" ? "" : " (it starts with the bytes 1f 8b)") +
                      ", which is not read here; decompress it and give that: zcat '" + path + "' > '" + plain + "'");
  }
}

LogFormat resolve_log_format(const std::string& path, std::optional<LogFormat> forced, const DaemonConfig& config) {
  if (forced) return *forced;
  if (config.input_format) return *config.input_format;
  return log_format_for_path(path);
}

std::unique_ptr<LogInput> open_log_input(const std::string& path, LogFormat format, const DaemonConfig& config) {
  refuse_unreadable_format(path);
  switch (format) {
    case LogFormat::kCandump: return std::make_unique<CandumpInput>(path);
    case LogFormat::kAsc: return std::make_unique<AscInput>(path);
    case LogFormat::kCsv:
      if (config.csv.map.empty()) {
        throw ConfigError(path + " is read as a CSV / scope export" +
                          (config.input_format ? std::string(" ([input] format)") : " (by its extension)") +
                          ", but " + (config.source.empty() ? std::string("no config was given") : config.source + " has no [input.csv.columns]") +
                          ": say which column holds what in [input.csv] (README: \"Scope and CSV exports\"), or "
                          "give --format candump|asc");
      }
      return std::make_unique<CsvInput>(path, config.csv);
  }
  return std::make_unique<CandumpInput>(path);
}

}  // namespace resolver
