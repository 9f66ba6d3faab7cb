// SocketCanSource::open() on this machine. On a kernel without CAN (CI, this
// container) the error path is the honest thing to test; on a bench PC with
// CAN the kernel-specific assertions skip with a message and the vcan suite
// (tests/vcan) covers the happy path.
#include <linux/can.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <string>

#include <gtest/gtest.h>

#include "drivers/socketcan/socketcan_source.h"

namespace resolver {
namespace {

// errno of socket(PF_CAN, SOCK_RAW, CAN_RAW), 0 when the kernel has CAN.
int can_socket_errno() {
  const int fd = ::socket(PF_CAN, SOCK_RAW, CAN_RAW);
  if (fd >= 0) {
    ::close(fd);
    return 0;
  }
  return errno;
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

TEST(SocketCanOpen, KernelWithoutCanGivesClearError) {
  const int err = can_socket_errno();
  if (err == 0) GTEST_SKIP() << "this kernel has CAN support; the no-CAN error path cannot be provoked";
  if (err != EAFNOSUPPORT) {
    GTEST_SKIP() << "socket(PF_CAN) failed with errno " << err << ", not EAFNOSUPPORT";
  }
  SocketCanOptions options;
  options.iface = "vcan0";
  try {
    (void)SocketCanSource::open(options);
    FAIL() << "open() succeeded although socket(PF_CAN) fails";
  } catch (const SocketCanError& e) {
    const std::string text = e.what();
    EXPECT_EQ(e.error_code(), EAFNOSUPPORT);
    EXPECT_EQ(e.iface(), "vcan0");
    EXPECT_TRUE(contains(text, "socket(PF_CAN, SOCK_RAW, CAN_RAW) on vcan0")) << text;
    EXPECT_TRUE(contains(text, "kernel has no CAN support")) << text;
    EXPECT_TRUE(contains(text, "modprobe can_raw")) << text;
  }
}

TEST(SocketCanOpen, MissingInterfaceNamesItAndHowToCreateIt) {
  if (can_socket_errno() != 0) GTEST_SKIP() << "kernel has no CAN support; see KernelWithoutCanGivesClearError";
  SocketCanOptions options;
  options.iface = "rsvnocan9";  // assumed absent on any bench PC
  try {
    (void)SocketCanSource::open(options);
    FAIL() << "open() of a missing interface succeeded";
  } catch (const SocketCanError& e) {
    const std::string text = e.what();
    EXPECT_TRUE(contains(text, "rsvnocan9")) << text;
    EXPECT_TRUE(contains(text, "no such interface")) << text;
  }
}

// Configuration mistakes are reported before any socket is created, so these
// behave the same with and without kernel CAN support.
TEST(SocketCanOpen, RejectsBadInterfaceNames) {
  for (const std::string& name : {std::string(), std::string("sixteen_chars_xx")}) {
    SocketCanOptions options;
    options.iface = name;
    try {
      (void)SocketCanSource::open(options);
      FAIL() << "accepted interface name '" << name << "'";
    } catch (const SocketCanError& e) {
      EXPECT_TRUE(contains(e.what(), "1 to 15 characters")) << e.what();
    }
  }
}

TEST(SocketCanOpen, RejectsFilterWiderThanItsFormat) {
  SocketCanOptions options;
  options.iface = "can0";
  options.filters.push_back({0x900, 0x7FF});
  try {
    (void)SocketCanSource::open(options);
    FAIL() << "accepted an 11-bit filter with id 0x900";
  } catch (const SocketCanError& e) {
    const std::string text = e.what();
    EXPECT_EQ(e.error_code(), EINVAL);
    EXPECT_TRUE(contains(text, "CAN_RAW_FILTER")) << text;
    EXPECT_TRUE(contains(text, "fix the filter")) << text;
  }
}

}  // namespace
}  // namespace resolver
