// resolver-echo --csv DIR: an LCM event log as tables, one CSV file per channel.
//
//   DIR/<channel>.csv   one header line, then one line per message of the channel:
//                       utime_s  the message's utime member [s] (the log's receive
//                                time when its type has none), to the microsecond;
//                       then every numeric member (LcmJsonDecoder's NumericField:
//                                nested members joined with '_', array elements as
//                                name_0, name_1 ...), in declaration order.
// The columns are the union over the channel's messages (a variable-length array
// may grow), in order of first appearance; a message without a column leaves its
// field empty (pandas and MATLAB's readtable read NaN). Strings are left out.
// Two passes over the log (columns, then rows): memory does not grow with its length.
// Messages that cannot be decoded (unknown type, corrupt bytes) are counted, not written.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "tools/echo/echo_output.h"
#include "tools/echo/lcm_json_decoder.h"

namespace resolver {

struct CsvChannelFile {
  std::string channel;
  std::string path;
  std::vector<std::string> types;  ///< full names of the types seen on the channel
  std::int64_t rows = 0;
  std::size_t columns = 0;         ///< utime_s included
};

struct CsvExportResult {
  std::vector<CsvChannelFile> files;  ///< in order of the channels' first message
  std::int64_t undecoded = 0;         ///< accepted by the filter but not decodable
  std::string first_undecoded_error;  ///< e.g. "unknown fingerprint 0x..." on channel X
};

/// The CSV file name of `channel` in `dir`: characters other than letters, digits,
/// '_', '-' and '.' become '_' (a channel name may hold '/'); a leading '.' too.
[[nodiscard]] std::string csv_file_name(const std::string& channel);

/// Writes the channels of the log at `log_path` that `filter` accepts into `dir`
/// (created when missing), stopping after `limit` messages when given.
/// Throws EventLogError on a malformed log (before any file is written) and
/// IoError "--csv: cannot write <path>: <reason>" (exit 3) when a file cannot be written.
CsvExportResult export_log_csv(const std::string& log_path, const LcmJsonDecoder& decoder, const EchoFilter& filter,
                               std::optional<std::int64_t> limit, const std::string& dir);

}  // namespace resolver
