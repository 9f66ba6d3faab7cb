#include "daemon/app/log_input.h"

#include <cmath>
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
      : ReaderInput(LogFormat::kCsv, path, config.format), decoder_(config.map), decimal_(config.format.decimal),
        row_rate_hz_(config.map.row_rate_hz) {
    // Read up to the first row so the column names are known and bound now:
    // a column the export lacks is a config error before anything runs.
    first_ = reader_.next(row_);
    if (auto missing = decoder_.bind(reader_.column_names())) {
      throw ConfigError(path + (reader_.names_line() > 0 ? ":" + std::to_string(reader_.names_line()) : std::string()) +
                        ": [input.csv.columns] " + *missing);
    }
  }
  Status next(LogRecord& record) override {
    record.is_row = true;
    CsvReader::Status st = CsvReader::Status::kEnd;
    if (first_) {
      st = *first_;
      first_.reset();
    } else {
      st = reader_.next(row_);
    }
    if (st == CsvReader::Status::kEnd) return Status::kEnd;
    if (st == CsvReader::Status::kBadLine) {
      problem_ = reader_.problem();
      return Status::kBadLine;
    }
    if (auto p = decoder_.decode(row_, decimal_, record.row)) {
      problem_ = std::move(*p);
      return Status::kBadLine;
    }
    record.timestamp_us =
        record.row.has_time ? record.row.time_us
                            : std::llround(static_cast<double>(record.row.sequence) * 1e6 / row_rate_hz_);
    return Status::kRecord;
  }

 private:
  RowDecoder decoder_;
  char decimal_;
  double row_rate_hz_;
  CsvRow row_;
  std::optional<CsvReader::Status> first_;
};

}  // namespace

LogFormat resolve_log_format(const std::string& path, std::optional<LogFormat> forced, const DaemonConfig& config) {
  if (forced) return *forced;
  if (config.input_format) return *config.input_format;
  return log_format_for_path(path);
}

std::unique_ptr<LogInput> open_log_input(const std::string& path, LogFormat format, const DaemonConfig& config) {
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
