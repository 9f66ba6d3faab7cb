// Control-message parsing: timestamps and the SO_RXQ_OVFL drop counter.
// Buffers are laid out with the libc CMSG_* macros, exactly as recvmsg() does.
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <time.h>
// After <time.h>: errqueue.h uses struct timespec without including it.
#include <linux/errqueue.h>

#include <array>
#include <cstring>
#include <ctime>
#include <vector>

#include <gtest/gtest.h>

#include "drivers/socketcan/can_cmsg.h"

namespace resolver {
namespace {

// Builds a control buffer one cmsg at a time.
class ControlBuffer {
 public:
  template <typename T>
  void add(int level, int type, const T& payload, std::size_t claimed_len = sizeof(T)) {
    const std::size_t offset = bytes_.size();
    bytes_.resize(offset + CMSG_SPACE(sizeof(T)), 0);
    cmsghdr header{};
    header.cmsg_level = level;
    header.cmsg_type = type;
    header.cmsg_len = CMSG_LEN(claimed_len);
    std::memcpy(bytes_.data() + offset, &header, sizeof header);
    std::memcpy(bytes_.data() + offset + CMSG_LEN(0), &payload, sizeof(T));
  }
  msghdr message() {
    msghdr msg{};
    msg.msg_control = bytes_.empty() ? nullptr : bytes_.data();
    msg.msg_controllen = bytes_.size();
    return msg;
  }

 private:
  // operator new aligns vector storage to alignof(std::max_align_t) >= alignof(cmsghdr).
  std::vector<unsigned char> bytes_;
};

constexpr std::int64_t kSec = 1'700'000'000;  // an arbitrary 2023 epoch second

TEST(SocketCanCmsg, EmptyControlGivesNothing) {
  ControlBuffer buffer;
  const msghdr msg = buffer.message();
  const ReceiveMetadata meta = parse_receive_cmsgs(msg);
  EXPECT_FALSE(meta.timestamp_us.has_value());
  EXPECT_EQ(meta.timestamp_kind, TimestampKind::kNone);
  EXPECT_FALSE(meta.drop_counter.has_value());
}

TEST(SocketCanCmsg, NanosecondTimestamp) {
  ControlBuffer buffer;
  timespec ts{};
  ts.tv_sec = kSec;
  ts.tv_nsec = 123'456'789;
  buffer.add(SOL_SOCKET, SCM_TIMESTAMPNS, ts);
  const msghdr msg = buffer.message();
  const ReceiveMetadata meta = parse_receive_cmsgs(msg);
  ASSERT_TRUE(meta.timestamp_us.has_value());
  EXPECT_EQ(*meta.timestamp_us, kSec * 1'000'000 + 123'456);
  EXPECT_EQ(meta.timestamp_ns, kSec * 1'000'000'000 + 123'456'789);  // full resolution kept
  EXPECT_EQ(meta.timestamp_kind, TimestampKind::kSoftwareNano);
}

TEST(SocketCanCmsg, MicrosecondTimestamp) {
  ControlBuffer buffer;
  timeval tv{};
  tv.tv_sec = kSec;
  tv.tv_usec = 654'321;
  buffer.add(SOL_SOCKET, SCM_TIMESTAMP, tv);
  const msghdr msg = buffer.message();
  const ReceiveMetadata meta = parse_receive_cmsgs(msg);
  ASSERT_TRUE(meta.timestamp_us.has_value());
  EXPECT_EQ(*meta.timestamp_us, kSec * 1'000'000 + 654'321);
  EXPECT_EQ(meta.timestamp_ns, kSec * 1'000'000'000 + 654'321'000);
  EXPECT_EQ(meta.timestamp_kind, TimestampKind::kSoftwareMicro);
}

TEST(SocketCanCmsg, NanosecondBeatsMicrosecondInEitherOrder) {
  timeval tv{};
  tv.tv_sec = kSec;
  tv.tv_usec = 1;
  timespec ts{};
  ts.tv_sec = kSec;
  ts.tv_nsec = 2'000;
  ControlBuffer micro_first;
  micro_first.add(SOL_SOCKET, SCM_TIMESTAMP, tv);
  micro_first.add(SOL_SOCKET, SCM_TIMESTAMPNS, ts);
  ControlBuffer nano_first;
  nano_first.add(SOL_SOCKET, SCM_TIMESTAMPNS, ts);
  nano_first.add(SOL_SOCKET, SCM_TIMESTAMP, tv);
  for (ControlBuffer* buffer : {&micro_first, &nano_first}) {
    const msghdr msg = buffer->message();
    const ReceiveMetadata meta = parse_receive_cmsgs(msg);
    EXPECT_EQ(meta.timestamp_us, kSec * 1'000'000 + 2);
  }
}

TEST(SocketCanCmsg, TimestampingPrefersRawHardware) {
  scm_timestamping stamps{};
  stamps.ts[0].tv_sec = kSec;
  stamps.ts[0].tv_nsec = 5'000;
  stamps.ts[2].tv_sec = 12;  // adapter clock, not the epoch
  stamps.ts[2].tv_nsec = 7'000;
  timespec software{};
  software.tv_sec = kSec;
  software.tv_nsec = 9'000;
  ControlBuffer buffer;
  buffer.add(SOL_SOCKET, SCM_TIMESTAMPNS, software);
  buffer.add(SOL_SOCKET, SCM_TIMESTAMPING, stamps);
  const msghdr msg = buffer.message();
  const ReceiveMetadata meta = parse_receive_cmsgs(msg);
  EXPECT_EQ(meta.timestamp_kind, TimestampKind::kHardware);
  EXPECT_EQ(meta.timestamp_us, 12 * 1'000'000 + 7);
}

TEST(SocketCanCmsg, TimestampingWithoutHardwareUsesSoftwareEntry) {
  scm_timestamping stamps{};
  stamps.ts[0].tv_sec = kSec;
  stamps.ts[0].tv_nsec = 5'000;
  ControlBuffer buffer;
  buffer.add(SOL_SOCKET, SCM_TIMESTAMPING, stamps);
  const msghdr msg = buffer.message();
  const ReceiveMetadata meta = parse_receive_cmsgs(msg);
  EXPECT_EQ(meta.timestamp_kind, TimestampKind::kSoftwareNano);
  EXPECT_EQ(meta.timestamp_us, kSec * 1'000'000 + 5);
}

TEST(SocketCanCmsg, DropCounter) {
  ControlBuffer buffer;
  const std::uint32_t drops = 4'000'000'123U;
  buffer.add(SOL_SOCKET, SO_RXQ_OVFL, drops);
  const msghdr msg = buffer.message();
  const ReceiveMetadata meta = parse_receive_cmsgs(msg);
  EXPECT_EQ(meta.drop_counter, drops);
  EXPECT_FALSE(meta.timestamp_us.has_value());
}

TEST(SocketCanCmsg, DropsSinceHandlesWrap) {
  EXPECT_EQ(drops_since(10, 17), 7U);
  EXPECT_EQ(drops_since(0xFFFFFFFEU, 3), 5U);
  EXPECT_EQ(drops_since(42, 42), 0U);
}

TEST(SocketCanCmsg, IgnoresOtherLevelsAndShortPayloads) {
  timespec ts{};
  ts.tv_sec = kSec;
  const std::uint32_t drops = 9;
  ControlBuffer buffer;
  buffer.add(SOL_IP, SCM_TIMESTAMPNS, ts);                       // wrong level
  buffer.add(SOL_SOCKET, SO_RXQ_OVFL, drops, sizeof(drops) - 1);  // claims too few bytes
  const msghdr msg = buffer.message();
  const ReceiveMetadata meta = parse_receive_cmsgs(msg);
  EXPECT_FALSE(meta.timestamp_us.has_value());
  EXPECT_FALSE(meta.drop_counter.has_value());
}

}  // namespace
}  // namespace resolver
