// SdNotifier against a fake $NOTIFY_SOCKET: a datagram socket bound in a temp
// dir (or in the abstract namespace) receives exactly what systemd would.
#include <gtest/gtest.h>

#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <cstddef>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <string>

#include "daemon/service/sd_notify.h"

namespace resolver {
namespace {

using std::chrono::microseconds;
using std::chrono::milliseconds;

std::int64_t now_monotonic_us() {
  timespec ts{};
  ::clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000 + static_cast<std::int64_t>(ts.tv_nsec) / 1000;
}

/// Plays systemd's side: a bound AF_UNIX datagram socket.
class FakeNotifySocket {
 public:
  /// `abstract` binds "@resolverd-test-<pid>-<n>" instead of a temp-dir path.
  explicit FakeNotifySocket(bool abstract) {
    static int counter = 0;
    fd_ = ::socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    EXPECT_GE(fd_, 0) << std::strerror(errno);
    sockaddr_un addr{};
    addr.sun_family = AF_UNIX;
    socklen_t len = 0;
    if (abstract) {
      const std::string name = "resolverd-test-" + std::to_string(::getpid()) + "-" + std::to_string(++counter);
      address_ = "@" + name;
      std::memcpy(addr.sun_path + 1, name.data(), name.size());
      len = static_cast<socklen_t>(offsetof(sockaddr_un, sun_path) + 1 + name.size());
    } else {
      char tmpl[] = "/tmp/resolverd-notify.XXXXXX";
      const char* dir = ::mkdtemp(tmpl);
      EXPECT_NE(dir, nullptr) << std::strerror(errno);
      dir_ = dir != nullptr ? dir : "/tmp";
      address_ = dir_ + "/notify";
      std::memcpy(addr.sun_path, address_.c_str(), address_.size() + 1);
      len = static_cast<socklen_t>(sizeof addr);
    }
    EXPECT_EQ(::bind(fd_, reinterpret_cast<const sockaddr*>(&addr), len), 0) << address_ << ": " << std::strerror(errno);
    timeval tv{};
    tv.tv_sec = 2;  // a missing message fails the test instead of hanging it
    ::setsockopt(fd_, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
  }
  ~FakeNotifySocket() {
    if (fd_ >= 0) ::close(fd_);
    if (!dir_.empty()) std::filesystem::remove_all(dir_);
  }
  FakeNotifySocket(const FakeNotifySocket&) = delete;
  FakeNotifySocket& operator=(const FakeNotifySocket&) = delete;

  [[nodiscard]] const std::string& address() const { return address_; }
  /// Closes and unlinks: later sends must fail.
  void vanish() {
    ::close(fd_);
    fd_ = -1;
    if (!dir_.empty()) std::filesystem::remove_all(dir_);
  }
  /// The next datagram, or "<timeout>".
  std::string receive() {
    char buf[4096];
    const ssize_t n = ::recv(fd_, buf, sizeof buf, 0);
    if (n < 0) return "<timeout>";
    return std::string(buf, static_cast<std::size_t>(n));
  }
  /// True when no datagram is waiting.
  bool empty() {
    char buf[16];
    return ::recv(fd_, buf, sizeof buf, MSG_DONTWAIT) < 0;
  }

 private:
  int fd_ = -1;
  std::string dir_;
  std::string address_;
};

/// Sets or clears the three variables systemd passes, for one test.
class NotifyEnv : public ::testing::Test {
 protected:
  void SetUp() override { clear(); }
  void TearDown() override { clear(); }
  static void clear() {
    ::unsetenv("NOTIFY_SOCKET");
    ::unsetenv("WATCHDOG_USEC");
    ::unsetenv("WATCHDOG_PID");
  }
};

TEST_F(NotifyEnv, WithoutNotifySocketEverythingIsANoOp) {
  SdNotifier n = SdNotifier::from_environment();
  EXPECT_FALSE(n.enabled());
  n.ready();
  n.status("x");
  n.watchdog();
  EXPECT_EQ(n.watchdog_interval(), microseconds(0));
  EXPECT_FALSE(n.send("READY=1"));
  EXPECT_EQ(n.send_failures(), 0U);  // disabled is not a failure
  EXPECT_TRUE(n.last_error().empty());
}

TEST_F(NotifyEnv, PathSocketReceivesExactMessages) {
  FakeNotifySocket fake(false);
  ::setenv("NOTIFY_SOCKET", fake.address().c_str(), 1);
  SdNotifier n = SdNotifier::from_environment();
  ASSERT_TRUE(n.enabled()) << n.last_error();
  n.ready();
  EXPECT_EQ(fake.receive(), "READY=1");
  n.status("can0: 4000.0 frames/s,\n0 rejected");
  EXPECT_EQ(fake.receive(), "STATUS=can0: 4000.0 frames/s, 0 rejected");
  n.watchdog();
  EXPECT_EQ(fake.receive(), "WATCHDOG=1");
  n.stopping();
  EXPECT_EQ(fake.receive(), "STOPPING=1");
  EXPECT_TRUE(fake.empty());
  EXPECT_EQ(n.send_failures(), 0U);
}

TEST_F(NotifyEnv, ReloadingCarriesMonotonicTimestamp) {
  FakeNotifySocket fake(false);
  SdNotifier n(fake.address(), microseconds(0));
  const std::int64_t before = now_monotonic_us();
  n.reloading();
  const std::int64_t after = now_monotonic_us();
  const std::string msg = fake.receive();
  const std::string prefix = "RELOADING=1\nMONOTONIC_USEC=";
  ASSERT_EQ(msg.substr(0, prefix.size()), prefix) << msg;
  const std::string digits = msg.substr(prefix.size());
  ASSERT_FALSE(digits.empty());
  ASSERT_EQ(digits.find_first_not_of("0123456789"), std::string::npos) << msg;
  const std::int64_t stamp = std::stoll(digits);
  EXPECT_GE(stamp, before);
  EXPECT_LE(stamp, after);
  n.ready();
  EXPECT_EQ(fake.receive(), "READY=1");
}

TEST_F(NotifyEnv, AbstractSocketName) {
  FakeNotifySocket fake(true);
  ASSERT_EQ(fake.address().front(), '@');
  ::setenv("NOTIFY_SOCKET", fake.address().c_str(), 1);
  SdNotifier n = SdNotifier::from_environment();
  ASSERT_TRUE(n.enabled()) << n.last_error();
  n.ready();
  EXPECT_EQ(fake.receive(), "READY=1");
}

TEST_F(NotifyEnv, WatchdogIntervalIsHalfOfWatchdogUsec) {
  FakeNotifySocket fake(false);
  ::setenv("NOTIFY_SOCKET", fake.address().c_str(), 1);
  ::setenv("WATCHDOG_USEC", "10000000", 1);
  EXPECT_EQ(SdNotifier::from_environment().watchdog_interval(), microseconds(5'000'000));
  ::setenv("WATCHDOG_PID", std::to_string(::getpid()).c_str(), 1);
  EXPECT_EQ(SdNotifier::from_environment().watchdog_interval(), microseconds(5'000'000));
  // Meant for another process (e.g. our parent): not ours to feed.
  ::setenv("WATCHDOG_PID", std::to_string(::getpid() + 1).c_str(), 1);
  EXPECT_EQ(SdNotifier::from_environment().watchdog_interval(), microseconds(0));
  ::unsetenv("WATCHDOG_PID");
  ::setenv("WATCHDOG_USEC", "ten seconds", 1);
  EXPECT_EQ(SdNotifier::from_environment().watchdog_interval(), microseconds(0));
  ::unsetenv("WATCHDOG_USEC");
  EXPECT_EQ(SdNotifier::from_environment().watchdog_interval(), microseconds(0));
}

TEST_F(NotifyEnv, MalformedNotifySocketDisablesWithReason) {
  ::setenv("NOTIFY_SOCKET", "relative/notify", 1);
  SdNotifier n = SdNotifier::from_environment();
  EXPECT_FALSE(n.enabled());
  EXPECT_NE(n.last_error().find("relative/notify"), std::string::npos) << n.last_error();
  EXPECT_NE(n.last_error().find("absolute path"), std::string::npos) << n.last_error();

  const std::string too_long = "/" + std::string(200, 'x');
  SdNotifier m(too_long, microseconds(0));
  EXPECT_FALSE(m.enabled());
  EXPECT_NE(m.last_error().find("longer than"), std::string::npos) << m.last_error();
}

TEST_F(NotifyEnv, VanishedListenerIsCountedNotFatal) {
  FakeNotifySocket fake(false);
  SdNotifier n(fake.address(), microseconds(0));
  const std::string address = fake.address();
  fake.vanish();
  EXPECT_FALSE(n.send("READY=1"));
  n.watchdog();
  EXPECT_EQ(n.send_failures(), 2U);
  EXPECT_NE(n.last_error().find(address), std::string::npos) << n.last_error();
  EXPECT_NE(n.last_error().find("WATCHDOG=1"), std::string::npos) << n.last_error();
}

TEST_F(NotifyEnv, MovedNotifierKeepsTheSocket) {
  FakeNotifySocket fake(false);
  SdNotifier a(fake.address(), microseconds(4000));
  SdNotifier b = std::move(a);
  EXPECT_FALSE(a.enabled());  // NOLINT(bugprone-use-after-move): moved-from state is specified
  ASSERT_TRUE(b.enabled());
  EXPECT_EQ(b.watchdog_interval(), microseconds(2000));
  b.ready();
  EXPECT_EQ(fake.receive(), "READY=1");
}

TEST(NotifyPacer, WatchdogAndStatusAtTheirPeriods) {
  using Clock = NotifyPacer::Clock;
  NotifyPacer pacer(milliseconds(500), milliseconds(1000));
  const Clock::time_point t0{};
  auto due = pacer.poll(t0);
  EXPECT_TRUE(due.watchdog);
  EXPECT_TRUE(due.status);
  due = pacer.poll(t0 + milliseconds(499));
  EXPECT_FALSE(due.watchdog);
  EXPECT_FALSE(due.status);
  due = pacer.poll(t0 + milliseconds(500));
  EXPECT_TRUE(due.watchdog);
  EXPECT_FALSE(due.status);
  due = pacer.poll(t0 + milliseconds(999));
  EXPECT_FALSE(due.watchdog);
  EXPECT_FALSE(due.status);
  due = pacer.poll(t0 + milliseconds(1000));
  EXPECT_TRUE(due.watchdog);
  EXPECT_TRUE(due.status);
  // A stall longer than several periods gives one ping, not a burst.
  due = pacer.poll(t0 + milliseconds(5000));
  EXPECT_TRUE(due.watchdog);
  due = pacer.poll(t0 + milliseconds(5001));
  EXPECT_FALSE(due.watchdog);
}

TEST(NotifyPacer, ZeroIntervalNeverDue) {
  NotifyPacer pacer(microseconds(0), microseconds(0));
  const NotifyPacer::Clock::time_point t0{};
  for (int i = 0; i < 3; ++i) {
    const auto due = pacer.poll(t0 + std::chrono::seconds(i * 100));
    EXPECT_FALSE(due.watchdog);
    EXPECT_FALSE(due.status);
  }
}

TEST(ServiceStatus, Format) {
  EXPECT_EQ(format_service_status("can0", 4000.04, 12, "crc 10, counter_gap 2", "alpha 1.23e-03"),
            "can0: 4000.0 frames/s, 12 rejected (crc 10, counter_gap 2), alpha 1.23e-03");
  EXPECT_EQ(format_service_status("vcan0", 0.0, 0, "", ""), "vcan0: 0.0 frames/s, 0 rejected");
}

}  // namespace
}  // namespace resolver
