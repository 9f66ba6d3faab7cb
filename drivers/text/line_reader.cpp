#include "drivers/text/line_reader.h"

#include <fcntl.h>
#include <poll.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <system_error>
#include <utility>

#include <fmt/format.h>

namespace resolver {

bool is_blank_line(std::string_view line) {
  return std::all_of(line.begin(), line.end(), [](char c) { return c == ' ' || c == '\t' || c == '\r'; });
}

TextProblem LineReader::too_long_problem(std::string_view expected) const {
  // No "path:line:" prefix: callers add it, as for every other problem.
  return TextProblem{"line_too_long", max_line_ + 1,
                     fmt::format("line is {} bytes long; at most {} are accepted - is this {}? The line was skipped",
                                 skipped_len_, max_line_, expected)};
}

LineReader::LineReader(const std::string& path, std::size_t max_line_length, std::size_t buffer_bytes)
    : path_(path),
      max_line_(max_line_length),
      buffer_bytes_(std::max(buffer_bytes, min_buffer_bytes(max_line_length))),
      // Not zeroed: only bytes read(2) wrote are ever looked at.
      buffer_(std::make_unique_for_overwrite<char[]>(buffer_bytes_)) {
  // O_NONBLOCK only for the open: a FIFO without a writer would block it, out of
  // reach of any stop flag. Reads are blocking again (and polled first, below).
  fd_ = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
  if (fd_ < 0) throw std::system_error(errno, std::generic_category(), "cannot open " + path);
  const int flags = ::fcntl(fd_, F_GETFL);
  if (flags >= 0) (void)::fcntl(fd_, F_SETFL, flags & ~O_NONBLOCK);
  struct stat st {};
  if (::fstat(fd_, &st) == 0 && S_ISREG(st.st_mode)) {
    total_bytes_ = static_cast<std::uint64_t>(st.st_size);
  } else {
    poll_before_read_ = true;
  }
}

LineReader::~LineReader() { close_fd(); }

LineReader::LineReader(LineReader&& other) noexcept
    : path_(std::move(other.path_)),
      fd_(std::exchange(other.fd_, -1)),
      max_line_(other.max_line_),
      buffer_bytes_(other.buffer_bytes_),
      buffer_(std::move(other.buffer_)),
      begin_(std::exchange(other.begin_, 0)),
      end_(std::exchange(other.end_, 0)),
      eof_(std::exchange(other.eof_, true)),
      line_number_(other.line_number_),
      skipped_len_(other.skipped_len_),
      bytes_consumed_(other.bytes_consumed_),
      total_bytes_(other.total_bytes_),
      stop_(other.stop_),
      stopped_(other.stopped_),
      poll_before_read_(other.poll_before_read_) {}

LineReader& LineReader::operator=(LineReader&& other) noexcept {
  if (this != &other) {
    close_fd();
    path_ = std::move(other.path_);
    fd_ = std::exchange(other.fd_, -1);
    max_line_ = other.max_line_;
    buffer_bytes_ = other.buffer_bytes_;
    buffer_ = std::move(other.buffer_);
    begin_ = std::exchange(other.begin_, 0);
    end_ = std::exchange(other.end_, 0);
    eof_ = std::exchange(other.eof_, true);
    line_number_ = other.line_number_;
    skipped_len_ = other.skipped_len_;
    bytes_consumed_ = other.bytes_consumed_;
    total_bytes_ = other.total_bytes_;
    stop_ = other.stop_;
    stopped_ = other.stopped_;
    poll_before_read_ = other.poll_before_read_;
  }
  return *this;
}

void LineReader::close_fd() noexcept {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
}

bool LineReader::wait_readable() {
  for (;;) {
    if (stop_ != nullptr && stop_->load(std::memory_order_relaxed)) return false;
    if (!poll_before_read_) return true;
    pollfd p{fd_, POLLIN, 0};
    // Linux reports a FIFO whose writer never came as not readable (no POLLHUP
    // until a writer has been and gone), so this waits for one.
    const int r = ::poll(&p, 1, stop_ != nullptr ? kStopPollMs : -1);
    if (r > 0) return true;  // data, end of input or an error: read() tells which
    if (r < 0 && errno != EINTR) {
      throw std::system_error(errno, std::generic_category(), "cannot wait for input from " + path_);
    }
  }
}

void LineReader::fill() {
  for (;;) {
    if (!wait_readable()) {
      stopped_ = true;
      eof_ = true;
      return;
    }
    const ssize_t n = ::read(fd_, buffer_.get() + end_, buffer_bytes_ - end_);
    if (n > 0) {
      end_ += static_cast<std::size_t>(n);
      return;
    }
    if (n == 0) {
      eof_ = true;
      return;
    }
    if (errno != EINTR) {
      throw std::system_error(errno, std::generic_category(),
                              fmt::format("read error in {} after {} bytes", path_, bytes_consumed_ + (end_ - begin_)));
    }
  }
}

LineReader::Result LineReader::next(std::string_view& line) {
  std::uint64_t skipped = 0;
  std::size_t scan_from = begin_;
  for (;;) {
    const void* found = std::memchr(buffer_.get() + scan_from, '\n', end_ - scan_from);
    if (found == nullptr && stopped_) return Result::kEnd;  // a partial line at a stop is not a bad line
    const bool at_end = found == nullptr && (eof_ || fd_ < 0);
    if (found != nullptr || at_end) {
      // A whole line (or the last one, which may lack its '\n').
      const std::size_t stop = found != nullptr ? static_cast<std::size_t>(static_cast<const char*>(found) - buffer_.get())
                                                : end_;
      const std::size_t len = stop - begin_;
      if (at_end && len == 0 && skipped == 0) return Result::kEnd;
      bytes_consumed_ += len + (found != nullptr ? 1 : 0);
      line = skipped > 0 ? std::string_view() : std::string_view(buffer_.get() + begin_, len);
      begin_ = found != nullptr ? stop + 1 : end_;
      ++line_number_;
      skipped_len_ = skipped + (skipped > 0 ? len : 0);
      return skipped > 0 ? Result::kTooLong : Result::kLine;
    }
    const std::size_t pending = end_ - begin_;
    if (pending > max_line_) {
      // Far too long to be a line: drop what we have and keep looking for its end.
      skipped += pending;
      bytes_consumed_ += pending;
      begin_ = end_ = 0;
      scan_from = 0;
    } else {
      std::memmove(buffer_.get(), buffer_.get() + begin_, pending);
      begin_ = 0;
      end_ = pending;
      scan_from = pending;
    }
    fill();
  }
}

}  // namespace resolver
