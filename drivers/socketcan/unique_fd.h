// Owns one file descriptor and closes it exactly once (RAII).
//
// Movable, not copyable. A moved-from UniqueFd holds -1 and closes nothing.
#pragma once

#include <unistd.h>

#include <utility>

namespace resolver {

class UniqueFd {
 public:
  UniqueFd() = default;
  explicit UniqueFd(int fd) : fd_(fd) {}
  ~UniqueFd() { reset(); }

  UniqueFd(const UniqueFd&) = delete;
  UniqueFd& operator=(const UniqueFd&) = delete;
  UniqueFd(UniqueFd&& other) noexcept : fd_(std::exchange(other.fd_, -1)) {}
  UniqueFd& operator=(UniqueFd&& other) noexcept {
    if (this != &other) {
      reset();
      fd_ = std::exchange(other.fd_, -1);
    }
    return *this;
  }

  [[nodiscard]] int get() const { return fd_; }
  [[nodiscard]] bool valid() const { return fd_ >= 0; }
  /// Gives up ownership without closing; returns the fd.
  [[nodiscard]] int release() { return std::exchange(fd_, -1); }
  /// Closes the held fd (if any). close() errors are ignored on purpose:
  /// on Linux the fd is released even when close() reports EINTR/EIO, and a
  /// receive-only socket has no buffered data to lose.
  void reset() {
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
  }

 private:
  int fd_ = -1;
};

}  // namespace resolver
