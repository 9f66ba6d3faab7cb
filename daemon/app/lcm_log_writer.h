// Writes LCM log files (the format of lcm-logger and LCM's file:// provider)
// with one buffered write per 256 KiB instead of liblcm's per-event stdio calls.
//
// Why our own: replaying a log into file:///...?mode=w spent about half of
// resolverd's time inside liblcm's file provider (docs/PERFORMANCE.md). The
// format is small and stable (LCM's eventlog.c): per event, big-endian
//   u32 sync 0xEDA1DA01 | i64 event number | i64 timestamp [us] |
//   i32 channel length | i32 data length | channel bytes | data bytes
// Files written here are read back by liblcm (lcm::LogFile, resolver-echo --log,
// lcm-logplayer) in the tests.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace resolver {

class LcmLogWriter {
 public:
  struct FileUrl {
    std::string path;
    bool append = false;
  };
  /// "file:///path?mode=w" (or mode=a) -> the path and mode. nullopt for any other
  /// URL, or file:// with other options, which stay with liblcm.
  [[nodiscard]] static std::optional<FileUrl> parse_url(std::string_view url);

  /// Opens (creates or truncates; appends with `append`). Throws std::system_error
  /// "cannot open <path> for the LCM log: <reason>".
  explicit LcmLogWriter(const FileUrl& file);
  ~LcmLogWriter();
  LcmLogWriter(const LcmLogWriter&) = delete;
  LcmLogWriter& operator=(const LcmLogWriter&) = delete;

  /// Starts an event and returns where its `data_size` bytes go (valid until the
  /// next call). `timestamp_us` is the event's log time.
  [[nodiscard]] std::uint8_t* begin_event(std::string_view channel, std::size_t data_size, std::int64_t timestamp_us);
  /// Writes what is buffered. False (and the error kept in error()) when the disk refuses.
  bool flush();
  [[nodiscard]] const std::string& error() const { return error_; }
  [[nodiscard]] std::int64_t events() const { return event_number_; }
  /// Events that were buffered when a write failed (they are not in the file).
  [[nodiscard]] std::int64_t lost() const { return lost_; }

 private:
  static constexpr std::size_t kFlushAt = std::size_t{256} * 1024;
  std::string path_;
  int fd_ = -1;
  std::vector<std::uint8_t> buffer_;
  std::size_t used_ = 0;
  std::int64_t event_number_ = 0;
  std::int64_t buffered_events_ = 0;
  std::int64_t lost_ = 0;
  std::string error_;
};

}  // namespace resolver
