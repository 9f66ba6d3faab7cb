#include "drivers/csv/csv_reader.h"

#include "drivers/csv/csv_number.h"

namespace resolver {

namespace {

constexpr std::string_view kUtf8Bom = "\xEF\xBB\xBF";

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\r'; }

/// Trims spaces and one pair of surrounding double quotes; returns the offset of what is left.
std::string_view trim_field(std::string_view field, std::size_t& offset) {
  std::size_t b = 0;
  std::size_t e = field.size();
  while (b < e && is_space(field[b])) ++b;
  while (e > b && is_space(field[e - 1])) --e;
  if (e - b >= 2 && field[b] == '"' && field[e - 1] == '"') {
    ++b;
    --e;
  }
  offset += b;
  return field.substr(b, e - b);
}

char delimiter_char(CsvFormat::Delimiter d) {
  switch (d) {
    case CsvFormat::Delimiter::kComma: return ',';
    case CsvFormat::Delimiter::kSemicolon: return ';';
    case CsvFormat::Delimiter::kTab: return '\t';
    case CsvFormat::Delimiter::kSpace:
    case CsvFormat::Delimiter::kAuto: break;
  }
  return ' ';
}

bool all_numbers(const CsvRow& row, char decimal) {
  if (row.fields.empty()) return false;
  for (const std::string_view f : row.fields) {
    if (!parse_csv_number(f, decimal)) return false;
  }
  return true;
}

}  // namespace

void split_csv_line(std::string_view line, CsvFormat::Delimiter delimiter, CsvRow& row) {
  row.fields.clear();
  row.columns.clear();
  while (!line.empty() && (line.back() == '\r' || line.back() == '\n')) line.remove_suffix(1);
  row.end_column = line.size() + 1;
  if (delimiter == CsvFormat::Delimiter::kSpace || delimiter == CsvFormat::Delimiter::kAuto) {
    std::size_t i = 0;
    while (i < line.size()) {
      while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
      if (i >= line.size()) break;
      const std::size_t start = i;
      while (i < line.size() && line[i] != ' ' && line[i] != '\t') ++i;
      std::size_t offset = start;
      row.fields.push_back(trim_field(line.substr(start, i - start), offset));
      row.columns.push_back(offset + 1);
    }
    return;
  }
  const char sep = delimiter_char(delimiter);
  std::size_t start = 0;
  for (;;) {
    const std::size_t stop = line.find(sep, start);
    const std::size_t end = stop == std::string_view::npos ? line.size() : stop;
    std::size_t offset = start;
    row.fields.push_back(trim_field(line.substr(start, end - start), offset));
    row.columns.push_back(offset + 1);
    if (stop == std::string_view::npos) break;
    start = stop + 1;
  }
}

CsvFormat::Delimiter detect_csv_delimiter(std::string_view line, char decimal) {
  if (line.find(';') != std::string_view::npos) return CsvFormat::Delimiter::kSemicolon;
  if (line.find('\t') != std::string_view::npos) return CsvFormat::Delimiter::kTab;
  if (decimal != ',' && line.find(',') != std::string_view::npos) return CsvFormat::Delimiter::kComma;
  return CsvFormat::Delimiter::kSpace;
}

CsvReader::CsvReader(const std::string& path, const CsvFormat& format, std::size_t buffer_bytes)
    : lines_(path, kMaxLineLength, buffer_bytes), format_(format), delimiter_(format.delimiter) {}

void CsvReader::set_names(std::string_view line) {
  const CsvFormat::Delimiter d = delimiter_ == CsvFormat::Delimiter::kAuto ? detect_csv_delimiter(line, format_.decimal)
                                                                            : delimiter_;
  split_csv_line(line, d, scratch_);
  names_.assign(scratch_.fields.begin(), scratch_.fields.end());
}

bool CsvReader::take_header_line(std::string_view line) {
  if (!format_.skip_until_numbers) {
    if (skipped_ < format_.header_lines) {
      ++skipped_;
      return true;
    }
    if (format_.column_names && names_line_ == 0) {
      names_line_ = lines_.line_number();
      set_names(line);
      return true;
    }
    return false;
  }
  // Skip until a line of numbers: the data starts there.
  const CsvFormat::Delimiter d = delimiter_ == CsvFormat::Delimiter::kAuto ? detect_csv_delimiter(line, format_.decimal)
                                                                            : delimiter_;
  split_csv_line(line, d, scratch_);
  if (all_numbers(scratch_, format_.decimal)) {
    if (format_.column_names && !last_skipped_.empty()) {
      names_line_ = last_skipped_line_;
      set_names(last_skipped_);
    }
    return false;
  }
  last_skipped_.assign(line);
  last_skipped_line_ = lines_.line_number();
  return true;
}

CsvReader::Status CsvReader::next(CsvRow& row) {
  for (;;) {
    std::string_view line;
    const LineReader::Result got = lines_.next(line);
    if (got == LineReader::Result::kEnd) return Status::kEnd;
    if (got == LineReader::Result::kTooLong) {
      problem_ = lines_.too_long_problem("a CSV export");
      return Status::kBadLine;
    }
    if (lines_.line_number() == 1 && line.starts_with(kUtf8Bom)) line.remove_prefix(kUtf8Bom.size());
    if (is_blank_line(line)) continue;
    if (!in_data_) {
      if (take_header_line(line)) continue;
      in_data_ = true;
      if (delimiter_ == CsvFormat::Delimiter::kAuto) delimiter_ = detect_csv_delimiter(line, format_.decimal);
    }
    split_csv_line(line, delimiter_, row);
    return Status::kRow;
  }
}

}  // namespace resolver
