// SocketCanSource::read()/write() through an injected AF_UNIX socketpair.
// SOCK_SEQPACKET and SOCK_DGRAM keep datagram boundaries like CAN_RAW does,
// and Linux delivers SO_TIMESTAMP(NS) cmsgs on AF_UNIX sockets, so the whole
// read path except the CAN-specific errnos runs without kernel CAN support.
#include <fcntl.h>
#include <linux/can.h>
#include <linux/can/error.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "drivers/socketcan/socketcan_source.h"

namespace resolver {
namespace {

using namespace std::chrono_literals;

std::int64_t now_us() {
  return std::chrono::duration_cast<std::chrono::microseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

// Peer end stays in the test; the other end goes into the source.
struct Pair {
  int peer = -1;
  SocketCanSource source;
};

Pair make_pair(int type, const std::string& iface = "vcan0") {
  int fds[2] = {-1, -1};
  if (::socketpair(AF_UNIX, type | SOCK_CLOEXEC, 0, fds) != 0) {
    throw std::runtime_error(std::string("socketpair: ") + std::strerror(errno));
  }
  return Pair{fds[0], SocketCanSource::adopt(fds[1], iface)};
}

void send_bytes(int fd, const void* data, std::size_t size) {
  ASSERT_EQ(::send(fd, data, size, 0), static_cast<ssize_t>(size)) << std::strerror(errno);
}

class SocketCanRead : public ::testing::TestWithParam<int> {
 protected:
  void SetUp() override {
    auto pair = make_pair(GetParam());
    peer_ = pair.peer;
    source_.emplace(std::move(pair.source));
    source_->set_read_timeout(2s);  // a frame is already queued in every test but the timeout one
  }
  void TearDown() override {
    if (peer_ >= 0) ::close(peer_);
  }
  int peer_ = -1;
  std::optional<SocketCanSource> source_;
};

TEST_P(SocketCanRead, ClassicFrameComesOutWithIfaceAndCounts) {
  can_frame raw{};
  raw.can_id = 0x100;
  raw.len = 8;
  for (std::uint8_t i = 0; i < 8; ++i) raw.data[i] = static_cast<std::uint8_t>(i + 1);
  send_bytes(peer_, &raw, sizeof raw);

  CanFrame frame;
  ASSERT_EQ(source_->read(frame), ReadStatus::kFrame);
  EXPECT_EQ(frame.id, 0x100U);
  EXPECT_FALSE(frame.fd);
  EXPECT_EQ(frame.len, 8);
  EXPECT_EQ(frame.data[7], 8);
  EXPECT_EQ(frame.iface_name(), "vcan0");
  EXPECT_EQ(source_->stats().frames, 1U);
  EXPECT_EQ(source_->stats().fd_frames, 0U);
}

TEST_P(SocketCanRead, FdFrameComesOutFromTheReadSize) {
  canfd_frame raw{};
  raw.can_id = 0x1ABCDEFU | CAN_EFF_FLAG;
  raw.len = 48;
  raw.flags = CANFD_BRS | CANFD_FDF;
  raw.data[47] = 0x5A;
  send_bytes(peer_, &raw, sizeof raw);

  CanFrame frame;
  ASSERT_EQ(source_->read(frame), ReadStatus::kFrame);
  EXPECT_TRUE(frame.fd);
  EXPECT_TRUE(frame.extended);
  EXPECT_EQ(frame.id, 0x1ABCDEFU);
  EXPECT_EQ(frame.fd_flags, CANFD_BRS);
  EXPECT_EQ(frame.len, 48);
  EXPECT_EQ(frame.data[47], 0x5A);
  EXPECT_EQ(source_->stats().fd_frames, 1U);
}

TEST_P(SocketCanRead, ErrorFrameIsCounted) {
  can_frame raw{};
  raw.can_id = CAN_ERR_FLAG | CAN_ERR_BUSOFF;
  raw.len = CAN_ERR_DLC;
  send_bytes(peer_, &raw, sizeof raw);

  CanFrame frame;
  ASSERT_EQ(source_->read(frame), ReadStatus::kFrame);
  EXPECT_TRUE(frame.error);
  EXPECT_EQ(frame.id, CAN_ERR_BUSOFF);
  EXPECT_EQ(source_->stats().error_frames, 1U);
  EXPECT_EQ(source_->stats().frames, 1U);
}

TEST_P(SocketCanRead, ShortAndOversizedDatagramsAreTruncatedThenReadingGoesOn) {
  const std::array<std::uint8_t, 10> short_read{};
  const std::array<std::uint8_t, 80> long_read{};
  can_frame good{};
  good.can_id = 0x101;
  good.len = 1;
  good.data[0] = 0x42;
  send_bytes(peer_, short_read.data(), short_read.size());
  send_bytes(peer_, long_read.data(), long_read.size());
  send_bytes(peer_, &good, sizeof good);

  CanFrame frame;
  frame.id = 0x3;
  EXPECT_EQ(source_->read(frame), ReadStatus::kTruncated);
  EXPECT_EQ(frame.id, 0x3U) << "a truncated read leaves the frame alone";
  EXPECT_EQ(source_->read(frame), ReadStatus::kTruncated) << "80 bytes > CANFD_MTU";
  EXPECT_EQ(source_->stats().truncated, 2U);
  ASSERT_EQ(source_->read(frame), ReadStatus::kFrame);
  EXPECT_EQ(frame.id, 0x101U);
  EXPECT_EQ(frame.data[0], 0x42);
  EXPECT_EQ(source_->stats().frames, 1U);
}

TEST_P(SocketCanRead, TimeoutWhenNothingArrives) {
  source_->set_read_timeout(30ms);
  CanFrame frame;
  const auto start = std::chrono::steady_clock::now();
  EXPECT_EQ(source_->read(frame), ReadStatus::kTimeout);
  const auto waited = std::chrono::steady_clock::now() - start;
  EXPECT_GE(waited, 25ms);
  EXPECT_LT(waited, 1s);
  EXPECT_EQ(source_->stats().timeouts, 1U);
  EXPECT_EQ(source_->stats().frames, 0U);
}

// Kernel timestamp vs fallback: the frame is sent, then read 60 ms later. A
// stamp from the cmsg lies in the send window; the CLOCK_REALTIME fallback
// lies after the delay.
constexpr auto kReadDelay = 60ms;

struct SendWindow {
  std::int64_t before_us;
  std::int64_t after_us;
  std::int64_t read_start_us;
};

SendWindow send_then_wait(int peer) {
  can_frame raw{};
  raw.can_id = 0x102;
  SendWindow window{};
  window.before_us = now_us();
  EXPECT_EQ(::send(peer, &raw, sizeof raw, 0), static_cast<ssize_t>(sizeof raw));
  window.after_us = now_us();
  std::this_thread::sleep_for(kReadDelay);
  window.read_start_us = now_us();
  return window;
}

TEST_P(SocketCanRead, TimestampComesFromNanosecondCmsg) {
  const int on = 1;
  ASSERT_EQ(::setsockopt(source_->fd(), SOL_SOCKET, SO_TIMESTAMPNS, &on, sizeof on), 0);
  const SendWindow window = send_then_wait(peer_);
  CanFrame frame;
  ASSERT_EQ(source_->read(frame), ReadStatus::kFrame);
  EXPECT_GE(frame.timestamp_us, window.before_us);
  EXPECT_LE(frame.timestamp_us, window.after_us);
  EXPECT_LT(frame.timestamp_us, window.read_start_us);
}

TEST_P(SocketCanRead, TimestampComesFromMicrosecondCmsg) {
  const int on = 1;
  ASSERT_EQ(::setsockopt(source_->fd(), SOL_SOCKET, SO_TIMESTAMP, &on, sizeof on), 0);
  const SendWindow window = send_then_wait(peer_);
  CanFrame frame;
  ASSERT_EQ(source_->read(frame), ReadStatus::kFrame);
  EXPECT_GE(frame.timestamp_us, window.before_us);
  EXPECT_LE(frame.timestamp_us, window.after_us);
}

TEST_P(SocketCanRead, TimestampFallsBackToReadTimeWithoutCmsg) {
  const SendWindow window = send_then_wait(peer_);
  CanFrame frame;
  ASSERT_EQ(source_->read(frame), ReadStatus::kFrame);
  EXPECT_GE(frame.timestamp_us, window.read_start_us);
  EXPECT_LE(frame.timestamp_us, now_us());
}

TEST_P(SocketCanRead, WriteSendsKernelImages) {
  CanFrame classic;
  classic.id = 0x1F0;
  classic.len = 8;
  classic.data[0] = 1;
  source_->write(classic);
  CanFrame fd;
  fd.id = 0x200;
  fd.fd = true;
  fd.fd_flags = CANFD_BRS;
  fd.len = 16;
  fd.data[15] = 0xAB;
  source_->write(fd);

  std::array<std::uint8_t, 128> buffer{};
  ASSERT_EQ(::recv(peer_, buffer.data(), buffer.size(), 0), static_cast<ssize_t>(CAN_MTU));
  can_frame got_classic{};
  std::memcpy(&got_classic, buffer.data(), sizeof got_classic);
  EXPECT_EQ(got_classic.can_id, 0x1F0U);
  EXPECT_EQ(got_classic.len, 8);
  EXPECT_EQ(got_classic.data[0], 1);

  ASSERT_EQ(::recv(peer_, buffer.data(), buffer.size(), 0), static_cast<ssize_t>(CANFD_MTU));
  canfd_frame got_fd{};
  std::memcpy(&got_fd, buffer.data(), sizeof got_fd);
  EXPECT_EQ(got_fd.can_id, 0x200U);
  EXPECT_EQ(got_fd.len, 16);
  EXPECT_EQ(got_fd.flags, CANFD_BRS);
  EXPECT_EQ(got_fd.data[15], 0xAB);
}

TEST_P(SocketCanRead, WriteRejectsInvalidFrameBeforeSending) {
  CanFrame frame;
  frame.id = 0x800;  // not an 11-bit ID
  EXPECT_THROW(source_->write(frame), std::invalid_argument);
  std::array<std::uint8_t, 128> buffer{};
  EXPECT_LT(::recv(peer_, buffer.data(), buffer.size(), MSG_DONTWAIT), 0);
  EXPECT_EQ(errno, EAGAIN);
}

INSTANTIATE_TEST_SUITE_P(Datagram, SocketCanRead, ::testing::Values(SOCK_SEQPACKET, SOCK_DGRAM),
                         [](const ::testing::TestParamInfo<int>& param_info) {
                           return std::string(param_info.param == SOCK_SEQPACKET ? "SeqPacket" : "Dgram");
                         });

TEST(SocketCanSource, PeerClosedSeqPacketIsDeviceGone) {
  Pair pair = make_pair(SOCK_SEQPACKET);
  ::close(pair.peer);
  CanFrame frame;
  EXPECT_EQ(pair.source.read(frame), ReadStatus::kDeviceGone);
}

void on_alarm(int) {}

struct AlarmedRead {
  ReadStatus status;
  std::chrono::steady_clock::duration waited;
};

/// read() with a 5 s timeout while SIGALRM (handler installed with
/// `sa_flags`) fires after 20 ms.
AlarmedRead read_with_alarm(int sa_flags) {
  Pair pair = make_pair(SOCK_DGRAM);
  pair.source.set_read_timeout(5s);
  struct sigaction action{};
  struct sigaction previous{};
  action.sa_handler = on_alarm;
  sigemptyset(&action.sa_mask);
  action.sa_flags = sa_flags;
  EXPECT_EQ(::sigaction(SIGALRM, &action, &previous), 0);
  itimerval timer{};
  timer.it_value.tv_usec = 20'000;  // [us] fire once after 20 ms
  EXPECT_EQ(::setitimer(ITIMER_REAL, &timer, nullptr), 0);
  CanFrame frame;
  const auto start = std::chrono::steady_clock::now();
  const ReadStatus status = pair.source.read(frame);
  const auto waited = std::chrono::steady_clock::now() - start;
  ::sigaction(SIGALRM, &previous, nullptr);
  ::close(pair.peer);
  return AlarmedRead{status, waited};
}

TEST(SocketCanSource, SignalDuringWaitIsInterrupted) {
  const AlarmedRead r = read_with_alarm(0);
  EXPECT_EQ(r.status, ReadStatus::kInterrupted);
  EXPECT_LT(r.waited, 4s);
}

TEST(SocketCanSource, SignalInterruptsTheWaitEvenWithSaRestart) {
  // read() waits in recvmsg with SO_RCVTIMEO, and such calls are never
  // restarted after a handler (signal(7)): the daemon's loop sees its flags
  // whatever flags another library installed its handlers with.
  const AlarmedRead r = read_with_alarm(SA_RESTART);
  EXPECT_EQ(r.status, ReadStatus::kInterrupted);
  EXPECT_LT(r.waited, 4s);
}

TEST(SocketCanSource, ZeroTimeoutDoesNotWaitAndLaterTimeoutsApply) {
  Pair pair = make_pair(SOCK_DGRAM);
  CanFrame frame;
  pair.source.set_read_timeout(0ms);  // the daemon's drain at SIGTERM
  auto start = std::chrono::steady_clock::now();
  EXPECT_EQ(pair.source.read(frame), ReadStatus::kTimeout);
  EXPECT_LT(std::chrono::steady_clock::now() - start, 20ms);
  pair.source.set_read_timeout(30ms);
  start = std::chrono::steady_clock::now();
  EXPECT_EQ(pair.source.read(frame), ReadStatus::kTimeout);
  EXPECT_GE(std::chrono::steady_clock::now() - start, 25ms);
  ::close(pair.peer);
}

TEST(SocketCanSource, AdoptedNonBlockingSocketStillWaitsForItsTimeout) {
  int fds[2] = {-1, -1};
  ASSERT_EQ(::socketpair(AF_UNIX, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0, fds), 0);
  SocketCanSource source = SocketCanSource::adopt(fds[0], "vcan0");
  source.set_read_timeout(30ms);
  CanFrame frame;
  const auto start = std::chrono::steady_clock::now();
  EXPECT_EQ(source.read(frame), ReadStatus::kTimeout);
  EXPECT_GE(std::chrono::steady_clock::now() - start, 25ms) << "a non-blocking fd made read() spin";
  ::close(fds[1]);
}

TEST(SocketCanSource, UnexpectedErrnoThrowsWithOperationAndIface) {
  // A pipe is readable but not a socket: recvmsg() fails with ENOTSOCK.
  int fds[2] = {-1, -1};
  ASSERT_EQ(::pipe2(fds, O_CLOEXEC), 0);
  SocketCanSource source = SocketCanSource::adopt(fds[0], "can7");
  const char byte = 1;
  ASSERT_EQ(::write(fds[1], &byte, 1), 1);
  CanFrame frame;
  try {
    (void)source.read(frame);
    FAIL() << "expected SocketCanError";
  } catch (const SocketCanError& e) {
    EXPECT_EQ(e.error_code(), ENOTSOCK);
    const std::string text = e.what();
    // The first call on the socket is the one setting the receive timeout.
    EXPECT_NE(text.find("setsockopt(SO_RCVTIMEO) on can7"), std::string::npos) << text;
    EXPECT_NE(text.find("not an open socket"), std::string::npos) << text;
  }
  ::close(fds[1]);
}

TEST(SocketCanSource, AdoptRejectsNegativeFd) {
  try {
    (void)SocketCanSource::adopt(-1, "can0");
    FAIL() << "expected SocketCanError";
  } catch (const SocketCanError& e) {
    EXPECT_EQ(e.error_code(), EBADF);
    EXPECT_NE(std::string(e.what()).find("can0"), std::string::npos);
  }
}

TEST(SocketCanSource, MoveTransfersOwnershipAndDestructorCloses) {
  Pair pair = make_pair(SOCK_DGRAM);
  const int fd = pair.source.fd();
  SocketCanSource moved = std::move(pair.source);
  EXPECT_EQ(moved.fd(), fd);
  EXPECT_EQ(pair.source.fd(), -1);  // NOLINT(bugprone-use-after-move): checking the moved-from state
  EXPECT_EQ(moved.iface(), "vcan0");
  {
    SocketCanSource sink = std::move(moved);
    EXPECT_GE(::fcntl(fd, F_GETFD), 0);
  }
  EXPECT_EQ(::fcntl(fd, F_GETFD), -1);
  EXPECT_EQ(errno, EBADF);
  ::close(pair.peer);
}

}  // namespace
}  // namespace resolver
