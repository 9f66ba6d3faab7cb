// Reader for LCM event logs (what lcm-logger and the file:// provider write).
//
// Each event is, big-endian:
//   uint32 sync word 0xEDA1DA01 | int64 event number | int64 timestamp [us]
//   int32 channel length | int32 data length | channel bytes | data bytes
//
// Read by hand instead of with lcm_eventlog_*: that API cannot say where a file
// is broken, and it silently skips garbage. Here every problem throws
// EventLogError naming the file, the event and the byte offset.
#pragma once

#include <cstdint>
#include <cstdio>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "daemon/core/errors.h"

namespace resolver {

class EventLogError : public InputError {
 public:
  /// A fault of the data (exit 1): the file was readable, its contents are not an LCM log.
  explicit EventLogError(const std::string& message) : InputError(Fault::kData, message) {}
};

struct LogEvent {
  std::int64_t event_number = 0;
  std::int64_t timestamp_us = 0;  ///< [us] when the logger received the message
  std::string channel;
  std::vector<std::uint8_t> data;
  std::uint64_t file_offset = 0;  ///< byte offset of the event's sync word
};

class EventLogReader {
 public:
  /// LCM refuses channel names longer than this; longer means a corrupt header.
  static constexpr std::int32_t kMaxChannelLength = 255;

  /// Opens `path`. Throws std::system_error if it cannot be opened, InputError (a usage
  /// fault) if it is not a regular file.
  explicit EventLogReader(std::string path);

  /// The next event, or nullopt at the clean end of the file.
  /// Throws EventLogError on a bad sync word, a truncated event or impossible
  /// lengths; later calls keep throwing the same error.
  std::optional<LogEvent> next();

  const std::string& path() const { return path_; }

 private:
  [[noreturn]] void fail(const std::string& what);

  struct FileCloser {
    void operator()(std::FILE* f) const { std::fclose(f); }
  };
  std::string path_;
  std::unique_ptr<std::FILE, FileCloser> file_;
  std::uint64_t file_size_ = 0;
  std::uint64_t offset_ = 0;
  std::int64_t events_read_ = 0;
  std::optional<std::string> error_;
};

}  // namespace resolver
