// SocketCanSource: construction, read loop and write. Setup of a real CAN_RAW
// socket lives in socketcan_open.cpp.
#include "drivers/socketcan/socketcan_source.h"

#include <fcntl.h>
#include <linux/sock_diag.h>
#include <poll.h>
#include <sys/socket.h>

#include <array>
#include <cerrno>
#include <climits>
#include <optional>
#include <utility>

#include "drivers/socketcan/can_cmsg.h"
#include "drivers/socketcan/can_wire.h"

namespace resolver {
namespace {

// [bytes] Room for every cmsg open() enables: SCM_TIMESTAMPING (3 x 16 + 16
// header), SCM_TIMESTAMPNS (16 + 16) and SO_RXQ_OVFL (4 + 16, padded to 24),
// about 120 bytes; 256 leaves slack for an adopted fd with other options.
constexpr std::size_t kControlBytes = 256;

/// SO_RCVTIMEO value for a read timeout: a zero timeval means "wait forever".
/// A zero timeout never reaches here (read() uses MSG_DONTWAIT instead).
timeval to_receive_timeout(std::chrono::milliseconds timeout) {
  timeval tv{};
  if (timeout.count() <= 0) return tv;
  tv.tv_sec = static_cast<time_t>(timeout.count() / 1000);
  tv.tv_usec = static_cast<suseconds_t>((timeout.count() % 1000) * 1000);
  return tv;
}

std::int64_t realtime_now_ns() {
  // system_clock is CLOCK_REALTIME on Linux, the clock SO_TIMESTAMP uses.
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

}  // namespace

SocketCanSource::SocketCanSource(UniqueFd fd, std::string iface,
                                 std::chrono::milliseconds read_timeout)
    : fd_(std::move(fd)), iface_(std::move(iface)), read_timeout_(read_timeout) {}

SocketCanSource SocketCanSource::adopt(int fd, std::string iface_name) {
  if (fd < 0) throw SocketCanError("adopt(fd " + std::to_string(fd) + ")", iface_name, EBADF);
  // read() waits inside recvmsg (SO_RCVTIMEO), which a non-blocking file
  // would turn into a busy loop of EAGAIN; socket activation may hand one over.
  const int status_flags = ::fcntl(fd, F_GETFL);
  if (status_flags >= 0 && (status_flags & O_NONBLOCK) != 0) ::fcntl(fd, F_SETFL, status_flags & ~O_NONBLOCK);
  return SocketCanSource(UniqueFd(fd), std::move(iface_name), SocketCanOptions{}.read_timeout);
}

void SocketCanSource::apply_receive_timeout() {
  // A zero timeout reads with MSG_DONTWAIT and leaves SO_RCVTIMEO alone, so
  // switching between polling and waiting costs no system call.
  if (read_timeout_.count() == 0 || (applied_timeout_ && *applied_timeout_ == read_timeout_)) return;
  const timeval tv = to_receive_timeout(read_timeout_);
  if (::setsockopt(fd_.get(), SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv) < 0) {
    throw SocketCanError("setsockopt(SO_RCVTIMEO)", iface_, errno);
  }
  applied_timeout_ = read_timeout_;
}

ReadStatus SocketCanSource::read(CanFrame& frame) {
  // One blocking recvmsg per frame, bounded by SO_RCVTIMEO: at a saturated
  // bus every frame wakes the reader, and a poll() before each recvmsg was a
  // second syscall per frame (docs/PERFORMANCE.md, live latency). A pending
  // socket error (ENETDOWN, ENODEV) wakes a blocked recvmsg and is returned
  // by it; a signal interrupts it with EINTR even under SA_RESTART, because
  // calls with a receive timeout are never restarted (signal(7)).
  apply_receive_timeout();
  const int flags = read_timeout_.count() == 0 ? MSG_DONTWAIT : 0;

  CanWireImage image{};
  iovec iov{};
  iov.iov_base = image.data();
  iov.iov_len = image.size();
  alignas(cmsghdr) std::array<unsigned char, kControlBytes> control{};
  msghdr msg{};
  msg.msg_iov = &iov;
  msg.msg_iovlen = 1;
  msg.msg_control = control.data();
  msg.msg_controllen = control.size();

  const ssize_t received = ::recvmsg(fd_.get(), &msg, flags);
  if (received < 0) {
    const int err = errno;
    switch (err) {
      case EAGAIN:  // SO_RCVTIMEO expired, or nothing queued under MSG_DONTWAIT
        ++stats_.timeouts;
        return ReadStatus::kTimeout;
      case EINTR:
        return ReadStatus::kInterrupted;
      case ENETDOWN:
        ++stats_.network_down;
        return ReadStatus::kNetworkDown;
      case ENODEV:
      case ENXIO:
        return ReadStatus::kDeviceGone;
      default:
        throw SocketCanError("recvmsg", iface_, err);
    }
  }
  // CAN_RAW never returns an empty read; a 0-byte read on a hung-up socket is
  // a stream/seqpacket peer that closed (adopted fds). Rare: poll only here.
  if (received == 0 && peer_hung_up()) return ReadStatus::kDeviceGone;

  // Drops are counted even when this read turns out to be malformed.
  const ReceiveMetadata meta = parse_receive_cmsgs(msg);
  if (meta.drop_counter) note_drop_counter(*meta.drop_counter);

  const auto size = static_cast<std::size_t>(received);
  if ((msg.msg_flags & MSG_TRUNC) != 0 ||
      decode_wire_frame(std::span<const std::uint8_t>(image.data(), size), frame) !=
          WireDecodeStatus::kOk) {
    ++stats_.truncated;
    return ReadStatus::kTruncated;
  }
  last_stamp_ns_ = meta.timestamp_ns ? *meta.timestamp_ns : realtime_now_ns();
  frame.timestamp_us = last_stamp_ns_ / 1000;
  frame.set_iface(iface_);
  ++stats_.frames;
  if (frame.fd) ++stats_.fd_frames;
  if (frame.error) ++stats_.error_frames;
  return ReadStatus::kFrame;
}

void SocketCanSource::note_drop_counter(std::uint32_t counter) {
  // The counter only grows, but a frame queued before the last SO_MEMINFO
  // reading carries an older value: take only what is ahead (mod 2^32).
  const std::uint32_t more = drops_since(last_drop_counter_, counter);
  if (more == 0 || more > 0x7FFFFFFFU) return;
  stats_.kernel_drops += more;
  last_drop_counter_ = counter;
}

void SocketCanSource::refresh_kernel_drops() {
  // SO_MEMINFO (Linux >= 4.12) reads the socket's drop counter now; without
  // it the count arrives only with the next frame queued (SO_RXQ_OVFL), so
  // the drops after the last frame of a run would never be seen.
  std::array<std::uint32_t, SK_MEMINFO_VARS> info{};
  socklen_t size = sizeof info;
  if (::getsockopt(fd_.get(), SOL_SOCKET, SO_MEMINFO, info.data(), &size) == 0 &&
      size >= (SK_MEMINFO_DROPS + 1) * sizeof(std::uint32_t)) {
    note_drop_counter(info[SK_MEMINFO_DROPS]);
  }
}

bool SocketCanSource::peer_hung_up() const {
  pollfd pfd{};
  pfd.fd = fd_.get();
  pfd.events = POLLIN;
  return ::poll(&pfd, 1, 0) == 1 && (pfd.revents & POLLHUP) != 0;
}

void SocketCanSource::write(const CanFrame& frame) {
  CanWireImage image{};
  const std::size_t size = encode_wire_frame(frame, image);
  using Clock = std::chrono::steady_clock;
  const std::optional<Clock::time_point> deadline =
      read_timeout_.count() < 0 ? std::nullopt : std::optional(Clock::now() + read_timeout_);
  for (;;) {
    // MSG_NOSIGNAL: a closed peer (adopted socketpair) gives EPIPE, not SIGPIPE.
    const ssize_t sent = ::send(fd_.get(), image.data(), size, MSG_NOSIGNAL);
    if (sent == static_cast<ssize_t>(size)) return;
    if (sent >= 0) {
      throw SocketCanError("write (" + std::to_string(sent) + " of " + std::to_string(size) +
                               " bytes sent)",
                           iface_, EIO, "the socket is not a CAN_RAW datagram socket");
    }
    const int err = errno;
    if (err == EINTR) continue;
    const bool queue_full = err == ENOBUFS || err == EAGAIN;
    if (queue_full && (!deadline || Clock::now() < *deadline)) {
      // CAN_RAW does not signal POLLOUT when the device queue drains, so
      // retry after 1 ms (about 4 classic frames at 500 kbit/s).
      ::poll(nullptr, 0, 1);
      continue;
    }
    throw SocketCanError("write", iface_, err);
  }
}

}  // namespace resolver
