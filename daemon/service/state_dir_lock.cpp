#include "daemon/service/state_dir_lock.h"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <cstring>
#include <string_view>

#include "daemon/core/errors.h"

namespace resolver {

namespace {

std::string lock_path(const std::string& dir) {
  if (!dir.empty() && dir.back() == '/') return dir + kStateLockFileName;
  return dir + "/" + kStateLockFileName;
}

/// The pid the holder wrote into the lock file, "" when it cannot be read (the
/// holder may not have written it yet).
std::string holder_pid(int fd) {
  std::array<char, 32> buf{};
  const ssize_t n = ::pread(fd, buf.data(), buf.size() - 1, 0);
  if (n <= 0) return "";
  std::string_view text(buf.data(), static_cast<std::size_t>(n));
  while (!text.empty() && (text.back() == '\n' || text.back() == ' ')) text.remove_suffix(1);
  for (const char ch : text) {
    if (ch < '0' || ch > '9') return "";
  }
  return std::string(text);
}

}  // namespace

StateDirLock StateDirLock::acquire(const std::string& dir) {
  const std::string path = lock_path(dir);
  // O_NONBLOCK: a FIFO put there must not hold the start up; it is refused below.
  const int fd = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC | O_NONBLOCK | O_NOFOLLOW, 0644);
  if (fd < 0) {
    throw IoError("cannot use --state-dir " + dir + ": opening the lock file " + path +
                  " failed: " + std::strerror(errno) +
                  "; the state directory must exist and be writable by resolverd (the calibration is saved there)");
  }
  struct stat st {};
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    ::close(fd);
    throw IoError("cannot use --state-dir " + dir + ": the lock file " + path + " is not a regular file; remove it");
  }
  if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
    const int err = errno;
    std::string problem;
    if (err == EWOULDBLOCK) {
      const std::string pid = holder_pid(fd);
      const std::string who = pid.empty() ? "another resolverd (pid not known yet)" : "another resolverd, pid " + pid;
      problem = "cannot use --state-dir " + dir + ": it is in use by " + who + " (it holds the lock " + path +
                "); two daemons on one state dir would overwrite each other's calibration: stop that one or give "
                "this one its own --state-dir";
    } else {
      problem = "cannot use --state-dir " + dir + ": locking " + path + " failed: " + std::strerror(err);
    }
    ::close(fd);
    throw IoError(problem);
  }
  const std::string pid = std::to_string(::getpid()) + "\n";
  // The pid is a courtesy for the message above: failing to write it is not fatal.
  if (::ftruncate(fd, 0) == 0) {
    [[maybe_unused]] const ssize_t written = ::pwrite(fd, pid.data(), pid.size(), 0);
  }
  return StateDirLock(fd);
}

void StateDirLock::release() {
  if (fd_ >= 0) ::close(fd_);  // releases the flock
  fd_ = -1;
}

}  // namespace resolver
