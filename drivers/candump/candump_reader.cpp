#include "drivers/candump/candump_reader.h"

#include <fcntl.h>
#include <poll.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <utility>

#include <fmt/format.h>

namespace resolver {
namespace {

bool is_blank_line(std::string_view line) {
  for (const char c : line) {
    if (c != ' ' && c != '\t' && c != '\r') return false;
  }
  return true;
}

std::string format_seconds(std::int64_t us) {
  return fmt::format("{}.{:06d}", us / 1'000'000, us % 1'000'000);
}

}  // namespace

CandumpReader::CandumpReader(const std::string& path, std::size_t buffer_bytes)
    : path_(path),
      buffer_bytes_(std::max(buffer_bytes, kMinBufferBytes)),
      // Not zeroed: only bytes read(2) wrote are ever looked at.
      buffer_(std::make_unique_for_overwrite<char[]>(buffer_bytes_)) {
  // O_NONBLOCK only for the open: a FIFO without a writer would block it, out of
  // reach of any stop flag. Reads are blocking again (and polled first, below).
  fd_ = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
  if (fd_ < 0) {
    throw std::runtime_error(fmt::format("cannot open {}: {}", path, std::strerror(errno)));
  }
  const int flags = ::fcntl(fd_, F_GETFL);
  if (flags >= 0) (void)::fcntl(fd_, F_SETFL, flags & ~O_NONBLOCK);
  struct stat st {};
  if (::fstat(fd_, &st) == 0 && S_ISREG(st.st_mode)) {
    total_bytes_ = static_cast<std::uint64_t>(st.st_size);
  } else {
    poll_before_read_ = true;
  }
}

CandumpReader::~CandumpReader() { close_fd(); }

CandumpReader::CandumpReader(CandumpReader&& other) noexcept
    : path_(std::move(other.path_)),
      fd_(std::exchange(other.fd_, -1)),
      buffer_bytes_(other.buffer_bytes_),
      buffer_(std::move(other.buffer_)),
      begin_(other.begin_),
      end_(other.end_),
      eof_(other.eof_),
      line_number_(other.line_number_),
      bytes_consumed_(other.bytes_consumed_),
      total_bytes_(other.total_bytes_),
      have_previous_(other.have_previous_),
      previous_timestamp_us_(other.previous_timestamp_us_),
      problem_(std::move(other.problem_)),
      stop_(other.stop_),
      stopped_(other.stopped_),
      poll_before_read_(other.poll_before_read_) {
  other.begin_ = other.end_ = 0;
  other.eof_ = true;
}

CandumpReader& CandumpReader::operator=(CandumpReader&& other) noexcept {
  if (this != &other) {
    close_fd();
    path_ = std::move(other.path_);
    fd_ = std::exchange(other.fd_, -1);
    buffer_bytes_ = other.buffer_bytes_;
    buffer_ = std::move(other.buffer_);
    begin_ = other.begin_;
    end_ = other.end_;
    eof_ = other.eof_;
    line_number_ = other.line_number_;
    bytes_consumed_ = other.bytes_consumed_;
    total_bytes_ = other.total_bytes_;
    have_previous_ = other.have_previous_;
    previous_timestamp_us_ = other.previous_timestamp_us_;
    problem_ = std::move(other.problem_);
    stop_ = other.stop_;
    stopped_ = other.stopped_;
    poll_before_read_ = other.poll_before_read_;
    other.begin_ = other.end_ = 0;
    other.eof_ = true;
  }
  return *this;
}

void CandumpReader::close_fd() noexcept {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
}

bool CandumpReader::wait_readable() {
  for (;;) {
    if (stop_ != nullptr && stop_->load(std::memory_order_relaxed)) return false;
    if (!poll_before_read_) return true;
    pollfd p{fd_, POLLIN, 0};
    // Linux reports a FIFO whose writer never came as not readable (no POLLHUP
    // until a writer has been and gone), so this waits for one.
    const int r = ::poll(&p, 1, stop_ != nullptr ? kStopPollMs : -1);
    if (r > 0) return true;  // data, end of input or an error: read() tells which
    if (r < 0 && errno != EINTR) {
      throw std::runtime_error(fmt::format("cannot wait for input from {}: {}", path_, std::strerror(errno)));
    }
  }
}

void CandumpReader::fill() {
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
      throw std::runtime_error(fmt::format("read error in {} after {} bytes: {}", path_,
                                           bytes_consumed_ + (end_ - begin_), std::strerror(errno)));
    }
  }
}

bool CandumpReader::take_line(std::string_view& line, std::uint64_t& skipped_len) {
  skipped_len = 0;
  std::size_t scan_from = begin_;
  for (;;) {
    const void* found = std::memchr(buffer_.get() + scan_from, '\n', end_ - scan_from);
    if (found != nullptr) {
      const auto newline = static_cast<std::size_t>(static_cast<const char*>(found) - buffer_.get());
      const std::size_t len = newline - begin_;
      if (skipped_len > 0) {
        skipped_len += len;
        line = {};
      } else {
        line = {buffer_.get() + begin_, len};
      }
      bytes_consumed_ += len + 1;
      begin_ = newline + 1;
      return true;
    }
    if (stopped_) return false;  // a partial line at a stop is not a bad line
    if (eof_ || fd_ < 0) {
      // The last line may lack its '\n'.
      const std::size_t len = end_ - begin_;
      if (len == 0 && skipped_len == 0) return false;
      if (skipped_len > 0) {
        skipped_len += len;
        line = {};
      } else {
        line = {buffer_.get() + begin_, len};
      }
      bytes_consumed_ += len;
      begin_ = end_;
      return true;
    }
    const std::size_t pending = end_ - begin_;
    if (pending > kMaxCandumpLineLength) {
      // Far too long to be a log line: drop what we have and keep looking for
      // its end, so one corrupt stretch cannot make the buffer grow.
      skipped_len += pending;
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

CandumpReader::Status CandumpReader::next(CanFrame& frame) {
  for (;;) {
    std::string_view line;
    std::uint64_t skipped_len = 0;
    if (!take_line(line, skipped_len)) return Status::kEnd;
    ++line_number_;
    if (skipped_len > 0) {
      problem_ = LogLineProblem{
          LogLineError::kLineTooLong, kMaxCandumpLineLength + 1,
          // No "path:line:" prefix: callers add it, as for every other problem.
          fmt::format("line is {} bytes long; at most {} are accepted - is this a candump -l log? "
                      "The line was skipped",
                      skipped_len, kMaxCandumpLineLength)};
      return Status::kBadLine;
    }
    if (is_blank_line(line)) continue;
    if (auto problem = parse_candump_line(line, frame)) {
      problem_ = std::move(*problem);
      return Status::kBadLine;
    }
    if (have_previous_ && frame.timestamp_us < previous_timestamp_us_) {
      problem_ = LogLineProblem{
          LogLineError::kNonMonotonicTimestamp, 2,
          fmt::format("timestamp {} s goes back from {} s of the previous frame; sort the log "
                      "by time (e.g. sort -s -k1,1) before replaying it",
                      format_seconds(frame.timestamp_us), format_seconds(previous_timestamp_us_))};
      return Status::kBadLine;
    }
    have_previous_ = true;
    previous_timestamp_us_ = frame.timestamp_us;
    return Status::kFrame;
  }
}

}  // namespace resolver
