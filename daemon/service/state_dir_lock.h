// One resolverd per state directory.
//
// Two daemons sharing a state dir would each load the other's calibration and
// overwrite it at exit, the last one to stop winning whatever it learned. So
// resolverd holds an exclusive flock(2) on `<state dir>/resolverd.lock` for its
// whole run and writes its pid into the file; a second resolverd finds the lock
// taken, reads the pid and refuses to start (exit 3, like any other resource it
// cannot have). The kernel drops the lock when the process ends, however it ends
// (a crash, SIGKILL), so a stale file never blocks a start; the file itself stays.
//
// Taking the lock also proves the directory is there and writable at start,
// rather than at the end of an eight-hour run when the calibration is saved.
#pragma once

#include <string>

namespace resolver {

/// Lock file name inside the state directory.
inline constexpr const char* kStateLockFileName = "resolverd.lock";

class StateDirLock {
 public:
  /// Takes the lock on `dir`, or throws IoError (exit 3, daemon/core/errors.h) naming
  /// the lock file, the reason (errno text, or the pid of the resolverd that holds it)
  /// and what to do. Never blocks (LOCK_NB; a FIFO in the lock file's place is refused).
  [[nodiscard]] static StateDirLock acquire(const std::string& dir);

  StateDirLock(StateDirLock&& other) noexcept : fd_(other.fd_) { other.fd_ = -1; }
  StateDirLock& operator=(StateDirLock&& other) noexcept {
    if (this != &other) {
      release();
      fd_ = other.fd_;
      other.fd_ = -1;
    }
    return *this;
  }
  StateDirLock(const StateDirLock&) = delete;
  StateDirLock& operator=(const StateDirLock&) = delete;
  ~StateDirLock() { release(); }

 private:
  void release();
  explicit StateDirLock(int fd) : fd_(fd) {}
  int fd_ = -1;
};

}  // namespace resolver
