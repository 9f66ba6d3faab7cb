#include "tools/echo/lcm_eventlog_reader.h"

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <system_error>
#include <sys/stat.h>

#include <fmt/format.h>

namespace resolver {

namespace {

constexpr std::uint32_t kSyncWord = 0xEDA1DA01;
// sync + event number + timestamp + channel length + data length
constexpr std::size_t kHeaderSize = 4 + 8 + 8 + 4 + 4;

std::uint64_t be(const std::uint8_t* p, std::size_t n) {
  std::uint64_t v = 0;
  for (std::size_t i = 0; i < n; ++i) v = (v << 8) | p[i];
  return v;
}

}  // namespace

EventLogReader::EventLogReader(std::string path) : path_(std::move(path)) {
  // A FIFO, pipe or device: the reader needs the file's size to tell a cut-off event
  // from the end. Looked at before opening: opening a FIFO waits for its writer.
  struct stat st {};
  if (::stat(path_.c_str(), &st) == 0 && !S_ISREG(st.st_mode)) {
    throw InputError(Fault::kUsage, fmt::format("{}: not a regular file; --log needs an LCM event log file (a FIFO or "
                                                "pipe: save it to a file first)", path_));
  }
  file_.reset(std::fopen(path_.c_str(), "rb"));
  if (!file_) {
    throw std::system_error(errno, std::generic_category(),
                            fmt::format("{}: cannot open the LCM log (check the path given to --log)", path_));
  }
  if (fstat(fileno(file_.get()), &st) != 0 || !S_ISREG(st.st_mode)) {
    throw InputError(Fault::kUsage, fmt::format("{}: not a regular file; --log needs an LCM event log file", path_));
  }
  file_size_ = static_cast<std::uint64_t>(st.st_size);
}

void EventLogReader::fail(const std::string& what) {
  error_ = fmt::format("{}: byte offset {} (event #{} in the file): {}", path_, offset_, events_read_ + 1, what);
  throw EventLogError(*error_);
}

std::optional<LogEvent> EventLogReader::next() {
  if (error_) throw EventLogError(*error_);
  if (offset_ == file_size_) return std::nullopt;

  const std::uint64_t left = file_size_ - offset_;
  std::uint8_t header[kHeaderSize];
  if (left < kHeaderSize) {
    // A short tail that does not even start with the sync word is garbage, not a cut-off event.
    std::uint8_t head[4] = {};
    const std::size_t n = std::fread(head, 1, std::min<std::uint64_t>(left, 4), file_.get());
    const std::uint8_t sync_bytes[4] = {0xED, 0xA1, 0xDA, 0x01};
    if (std::memcmp(head, sync_bytes, n) != 0) {
      fail(fmt::format("expected the event sync word 0x{:08X}; {}", kSyncWord,
                       offset_ == 0 ? "this is not an LCM event log" : "the log is corrupt after this point"));
    }
    fail(fmt::format("truncated event header: {} byte(s) left, a header needs {}; the log was probably cut off "
                     "while being written (the events before this one are fine)",
                     left, kHeaderSize));
  }
  if (std::fread(header, 1, kHeaderSize, file_.get()) != kHeaderSize) {
    fail(fmt::format("read error ({})", std::strerror(errno)));
  }
  const auto sync = static_cast<std::uint32_t>(be(header, 4));
  if (sync != kSyncWord) {
    fail(fmt::format("expected the event sync word 0x{:08X} but found 0x{:08X}; {}", kSyncWord, sync,
                     offset_ == 0 ? "this is not an LCM event log" : "the log is corrupt after this point"));
  }
  LogEvent ev;
  ev.file_offset = offset_;
  ev.event_number = static_cast<std::int64_t>(be(header + 4, 8));
  ev.timestamp_us = static_cast<std::int64_t>(be(header + 12, 8));
  const auto channel_len = static_cast<std::int32_t>(be(header + 20, 4));
  const auto data_len = static_cast<std::int32_t>(be(header + 24, 4));
  if (channel_len <= 0 || channel_len > kMaxChannelLength) {
    fail(fmt::format("channel name length {} is impossible (1..{}); the event header is corrupt", channel_len,
                     kMaxChannelLength));
  }
  if (data_len < 0) fail(fmt::format("message length {} is negative; the event header is corrupt", data_len));
  const std::uint64_t body = static_cast<std::uint64_t>(channel_len) + static_cast<std::uint64_t>(data_len);
  if (body > left - kHeaderSize) {
    fail(fmt::format("truncated event: the header announces {} channel + {} data bytes but only {} remain; the log "
                     "was probably cut off while being written (the events before this one are fine)",
                     channel_len, data_len, left - kHeaderSize));
  }
  ev.channel.resize(static_cast<std::size_t>(channel_len));
  ev.data.resize(static_cast<std::size_t>(data_len));
  if (std::fread(ev.channel.data(), 1, ev.channel.size(), file_.get()) != ev.channel.size() ||
      std::fread(ev.data.data(), 1, ev.data.size(), file_.get()) != ev.data.size()) {
    fail(fmt::format("read error ({})", std::strerror(errno)));
  }
  offset_ += kHeaderSize + body;
  ++events_read_;
  return ev;
}

}  // namespace resolver
