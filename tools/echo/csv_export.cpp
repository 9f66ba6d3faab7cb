#include "tools/echo/csv_export.h"

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <map>
#include <memory>
#include <unordered_map>

#include <fmt/format.h>

#include "daemon/core/errors.h"
#include "tools/echo/lcm_eventlog_reader.h"

namespace resolver {

namespace {

/// [s] with six decimals: a microsecond utime exactly (a double would round at 2^53 us).
std::string seconds_text(std::int64_t utime_us) {
  const bool negative = utime_us < 0;
  // Magnitude in unsigned arithmetic: -INT64_MIN does not fit an int64.
  const std::uint64_t magnitude =
      negative ? std::uint64_t{0} - static_cast<std::uint64_t>(utime_us) : static_cast<std::uint64_t>(utime_us);
  return fmt::format("{}{}.{:06}", negative ? "-" : "", magnitude / 1000000U, magnitude % 1000000U);
}

/// The time column of one message: its utime member (JSON text of an integer, or of
/// a floating-point value in a type that declares utime as double), else the log's time.
std::string time_text(const DecodedMessage& msg, std::int64_t receive_utime) {
  if (!msg.utime_json) return seconds_text(receive_utime);
  const std::string& text = *msg.utime_json;
  std::int64_t integer = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), integer);
  if (ec == std::errc() && end == text.data() + text.size()) return seconds_text(integer);
  if (text == "null") return "NaN";  // a NaN or infinite double utime
  char* parse_end = nullptr;
  const double us = std::strtod(text.c_str(), &parse_end);
  if (parse_end == text.c_str()) return "NaN";
  return fmt::format("{}", us * 1e-6);
}

struct Channel {
  CsvChannelFile file;
  std::vector<std::string> columns;                       ///< without utime_s
  std::unordered_map<std::string, std::size_t> index_of;  ///< column name -> position in `columns`
  std::FILE* out = nullptr;
};

struct FileCloser {
  void operator()(std::FILE* f) const { std::fclose(f); }
};

/// Calls `each(event, decoded)` for the messages `filter` accepts, up to `limit`;
/// counts those that cannot be decoded instead.
template <typename Each>
void for_each_message(const std::string& log_path, const LcmJsonDecoder& decoder, const EchoFilter& filter,
                      std::optional<std::int64_t> limit, CsvExportResult* counts, Each each) {
  EventLogReader reader(log_path);
  std::int64_t taken = 0;
  while (!limit || taken < *limit) {
    const std::optional<LogEvent> ev = reader.next();
    if (!ev) break;
    if (!filter.channel_matches(ev->channel)) continue;
    DecodedMessage msg = decoder.decode(ev->data, true);
    if (!filter.type_matches(msg.type)) continue;
    ++taken;
    if (!msg.error.empty()) {
      if (counts != nullptr) {
        if (counts->undecoded == 0) counts->first_undecoded_error = fmt::format("{} on channel {}", msg.error, ev->channel);
        ++counts->undecoded;
      }
      continue;
    }
    each(*ev, msg);
  }
}

}  // namespace

std::string csv_file_name(const std::string& channel) {
  std::string name = channel.empty() ? std::string("_") : channel;
  for (char& c : name) {
    const bool keep = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' ||
                      c == '-' || c == '.';
    if (!keep) c = '_';
  }
  if (name.front() == '.') name.front() = '_';  // no hidden files, no "." or ".."
  return name + ".csv";
}

CsvExportResult export_log_csv(const std::string& log_path, const LcmJsonDecoder& decoder, const EchoFilter& filter,
                               std::optional<std::int64_t> limit, const std::string& dir) {
  CsvExportResult result;
  // Pass 1: the channels, their types and columns (a malformed log throws here, before any file exists).
  std::vector<Channel> channels;
  std::map<std::string, std::size_t> channel_index;
  for_each_message(log_path, decoder, filter, limit, &result, [&](const LogEvent& ev, const DecodedMessage& msg) {
    auto [it, added] = channel_index.try_emplace(ev.channel, channels.size());
    if (added) {
      channels.emplace_back();
      channels.back().file.channel = ev.channel;
    }
    Channel& ch = channels[it->second];
    const std::string type = msg.type->full_name();
    if (std::find(ch.file.types.begin(), ch.file.types.end(), type) == ch.file.types.end()) ch.file.types.push_back(type);
    for (const NumericField& f : msg.numbers) {
      if (ch.index_of.try_emplace(f.name, ch.columns.size()).second) ch.columns.push_back(f.name);
    }
  });

  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw IoError(fmt::format("cannot write {}: {}", dir, ec.message()), Where::at_option("--csv"));
  std::vector<std::unique_ptr<std::FILE, FileCloser>> files;
  std::map<std::string, int> names_used;  // two channels that map to one file name get -2, -3 ...
  for (Channel& ch : channels) {
    std::string name = csv_file_name(ch.file.channel);
    if (const int n = ++names_used[name]; n > 1) name = fmt::format("{}-{}.csv", name.substr(0, name.size() - 4), n);
    ch.file.path = (std::filesystem::path(dir) / name).string();
    ch.file.columns = ch.columns.size() + 1;
    files.emplace_back(std::fopen(ch.file.path.c_str(), "wb"));
    ch.out = files.back().get();
    if (ch.out == nullptr) {
      throw IoError(fmt::format("cannot write {}: {}", ch.file.path, std::strerror(errno)), Where::at_option("--csv"));
    }
    std::string header = "utime_s";
    for (const std::string& c : ch.columns) header += "," + c;
    header += '\n';
    if (std::fputs(header.c_str(), ch.out) == EOF) {
      throw IoError(fmt::format("cannot write {}: {}", ch.file.path, std::strerror(errno)), Where::at_option("--csv"));
    }
  }

  // Pass 2: the rows.
  std::vector<std::string> fields;
  for_each_message(log_path, decoder, filter, limit, nullptr, [&](const LogEvent& ev, const DecodedMessage& msg) {
    Channel& ch = channels[channel_index.at(ev.channel)];
    fields.assign(ch.columns.size(), std::string());
    for (const NumericField& f : msg.numbers) fields[ch.index_of.at(f.name)] = f.text;
    std::string line = time_text(msg, ev.timestamp_us);
    for (const std::string& f : fields) {
      line += ',';
      line += f;
    }
    line += '\n';
    if (std::fwrite(line.data(), 1, line.size(), ch.out) != line.size()) {
      throw IoError(fmt::format("cannot write {}: {}", ch.file.path, std::strerror(errno)), Where::at_option("--csv"));
    }
    ++ch.file.rows;
  });
  for (std::size_t i = 0; i < channels.size(); ++i) {
    std::FILE* f = files[i].release();
    if (std::fclose(f) != 0) {
      throw IoError(fmt::format("cannot write {}: {}", channels[i].file.path, std::strerror(errno)),
                    Where::at_option("--csv"));
    }
    result.files.push_back(std::move(channels[i].file));
  }
  return result;
}

}  // namespace resolver
