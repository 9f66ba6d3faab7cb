// How a CSV or scope export is laid out ([input.csv] in resolverd's config):
// separator, decimal mark, lines before the data, whether a line names the
// columns. What the columns mean is the row map's business (daemon/decode/row_decoder.h).
#pragma once

namespace resolver {

struct CsvFormat {
  enum class Delimiter {
    kAuto,       ///< from the first data line: ';' if present, else tab, else ',' (unless ',' is the decimal mark), else spaces
    kComma,
    kSemicolon,
    kTab,
    kSpace,      ///< runs of spaces and tabs (fixed-width and space-separated exports)
  };
  Delimiter delimiter = Delimiter::kAuto;
  char decimal = '.';      ///< '.' or ',' (German/French locale exports)
  int header_lines = 0;    ///< lines skipped before the column-name line (or the data)
  /// Skip lines until one whose fields are all numbers (header_lines = "auto");
  /// with column_names the last skipped line names the columns.
  bool skip_until_numbers = false;
  bool column_names = true;  ///< the first line after the skipped ones names the columns
};

}  // namespace resolver
