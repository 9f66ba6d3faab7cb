// SocketCanError: what, where, errno text and the hint.
#include <cerrno>
#include <cstring>
#include <string>

#include <gtest/gtest.h>

#include "drivers/socketcan/socketcan_error.h"

namespace resolver {
namespace {

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

TEST(SocketCanErrorMessage, NamesOperationInterfaceErrnoAndHint) {
  const SocketCanError error("bind", "can1", ENODEV);
  const std::string text = error.what();
  EXPECT_EQ(text.rfind("bind on can1: ", 0), 0U) << text;
  EXPECT_TRUE(contains(text, std::strerror(ENODEV))) << text;
  EXPECT_TRUE(contains(text, "(errno " + std::to_string(ENODEV) + ")")) << text;
  EXPECT_TRUE(contains(text, "no such interface")) << text;
  EXPECT_EQ(error.error_code(), ENODEV);
  EXPECT_EQ(error.operation(), "bind");
  EXPECT_EQ(error.iface(), "can1");
}

TEST(SocketCanErrorMessage, HintsForCommonBenchProblems) {
  EXPECT_TRUE(contains(SocketCanError("socket", "can0", EAFNOSUPPORT).what(),
                       "kernel has no CAN support: modprobe can_raw"));
  EXPECT_TRUE(contains(SocketCanError("recvmsg", "can2", ENETDOWN).what(),
                       "interface is down: ip link set can2 up"));
  EXPECT_TRUE(contains(SocketCanError("write", "can0", ENOBUFS).what(), "txqueuelen"));
  EXPECT_TRUE(contains(SocketCanError("write", "vcan0", EINVAL).what(), "mtu 72"));
}

TEST(SocketCanErrorMessage, ExplicitHintReplacesDefault) {
  const SocketCanError error("check interface name", "x", EINVAL, "use 1 to 15 characters");
  EXPECT_TRUE(contains(error.what(), "; use 1 to 15 characters"));
  EXPECT_EQ(error.error_code(), EINVAL);
}

TEST(SocketCanErrorMessage, NoTrailingSeparatorWithoutHint) {
  const std::string text = SocketCanError("poll", "can0", EDOM).what();
  EXPECT_EQ(text.back(), ')') << text;
}

}  // namespace
}  // namespace resolver
