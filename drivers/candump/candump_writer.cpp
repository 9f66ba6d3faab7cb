#include "drivers/candump/candump_writer.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <system_error>

#include <fmt/format.h>

#include "drivers/candump/candump_line.h"

namespace resolver {
namespace {

// [bytes] flush threshold: ~1500 lines per write(2).
constexpr std::size_t kFlushBytes = std::size_t{64} << 10;
// [bytes] headroom so appending one line never reallocates (a line is < 256).
constexpr std::size_t kLineHeadroom = 256;

}  // namespace

CandumpWriter::CandumpWriter(const std::string& path) : path_(path), line_at_(Where::at_file(path)) {
  fd_ = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd_ < 0) {
    throw std::system_error(errno, std::generic_category(), "cannot create " + path);
  }
  buffer_.reserve(kFlushBytes + kLineHeadroom);
}

CandumpWriter::~CandumpWriter() {
  try {
    close();
  } catch (...) {
    // Destructors must not throw; close() explicitly to see the error.
  }
}

void CandumpWriter::write(const CanFrame& frame) {
  if (fd_ < 0) {
    throw std::runtime_error(fmt::format("write to {} after close()", path_));
  }
  line_at_.line = frames_written_ + 1;  // one line a frame
  check_loggable(frame, line_at_);
  append_candump_line(frame, buffer_);
  ++frames_written_;
  if (buffer_.size() >= kFlushBytes) flush();
}

void CandumpWriter::flush() {
  std::size_t done = 0;
  while (done < buffer_.size()) {
    const ssize_t n = ::write(fd_, buffer_.data() + done, buffer_.size() - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      const int err = errno;
      buffer_.clear();  // do not retry the same bytes from the destructor
      throw std::system_error(err, std::generic_category(), "write error on " + path_);
    }
    done += static_cast<std::size_t>(n);
  }
  buffer_.clear();
}

void CandumpWriter::close() {
  if (fd_ < 0) return;
  try {
    flush();
  } catch (...) {
    ::close(fd_);
    fd_ = -1;
    throw;
  }
  const int fd = fd_;
  fd_ = -1;
  if (::close(fd) != 0) {
    throw std::system_error(errno, std::generic_category(), "close of " + path_ + " failed");
  }
}

}  // namespace resolver
