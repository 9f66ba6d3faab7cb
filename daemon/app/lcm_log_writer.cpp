#include "daemon/app/lcm_log_writer.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <system_error>

namespace resolver {

namespace {

constexpr std::uint32_t kSync = 0xEDA1DA01U;
constexpr std::size_t kHeaderBytes = 4 + 8 + 8 + 4 + 4;

std::uint8_t* put_be(std::uint8_t* p, std::uint64_t v, int bytes) {
  for (int i = bytes - 1; i >= 0; --i) *p++ = static_cast<std::uint8_t>(v >> (8 * i));
  return p;
}

}  // namespace

std::optional<LcmLogWriter::FileUrl> LcmLogWriter::parse_url(std::string_view url) {
  constexpr std::string_view kScheme = "file://";
  if (url.substr(0, kScheme.size()) != kScheme) return std::nullopt;
  const std::string_view rest = url.substr(kScheme.size());
  const std::size_t q = rest.find('?');
  if (q == std::string_view::npos) return std::nullopt;  // liblcm's default mode is read
  FileUrl out;
  out.path = std::string(rest.substr(0, q));
  const std::string_view query = rest.substr(q + 1);
  if (query == "mode=w") out.append = false;
  else if (query == "mode=a") out.append = true;
  else return std::nullopt;
  if (out.path.empty()) return std::nullopt;
  return out;
}

LcmLogWriter::LcmLogWriter(const FileUrl& file) : path_(file.path), buffer_(kFlushAt + 4096) {
  const int flags = O_WRONLY | O_CREAT | O_CLOEXEC | (file.append ? O_APPEND : O_TRUNC);
  fd_ = ::open(path_.c_str(), flags, 0644);
  if (fd_ < 0) throw std::system_error(errno, std::generic_category(), "cannot open " + path_ + " for the LCM log");
}

LcmLogWriter::~LcmLogWriter() {
  (void)flush();
  if (fd_ >= 0) ::close(fd_);
}

std::uint8_t* LcmLogWriter::begin_event(std::string_view channel, std::size_t data_size, std::int64_t timestamp_us) {
  const std::size_t need = kHeaderBytes + channel.size() + data_size;
  if (used_ + need > kFlushAt) (void)flush();
  if (used_ + need > buffer_.size()) buffer_.resize(used_ + need);
  std::uint8_t* p = buffer_.data() + used_;
  p = put_be(p, kSync, 4);
  p = put_be(p, static_cast<std::uint64_t>(event_number_++), 8);
  p = put_be(p, static_cast<std::uint64_t>(timestamp_us), 8);
  p = put_be(p, channel.size(), 4);
  p = put_be(p, data_size, 4);
  std::memcpy(p, channel.data(), channel.size());
  p += channel.size();
  used_ += need;
  ++buffered_events_;
  return p;
}

bool LcmLogWriter::flush() {
  std::size_t done = 0;
  while (done < used_) {
    const ssize_t n = ::write(fd_, buffer_.data() + done, used_ - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      error_ = "writing " + path_ + ": " + std::strerror(errno);
      used_ = 0;
      lost_ += buffered_events_;
      buffered_events_ = 0;
      return false;
    }
    done += static_cast<std::size_t>(n);
  }
  used_ = 0;
  buffered_events_ = 0;
  return true;
}

}  // namespace resolver
