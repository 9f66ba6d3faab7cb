// SplitWakeSource through two injected AF_UNIX socket pairs, one per socket:
// the test routes each frame the way the kernel's CAN_RAW filters would
// (waking IDs to one, every other ID to the other) and checks that read()
// gives back exactly the frames sent, in the order sent.
#include <sys/socket.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "drivers/socketcan/can_wire.h"
#include "drivers/socketcan/split_wake_source.h"

namespace resolver {
namespace {

using namespace std::chrono_literals;

constexpr std::uint32_t kWakeId = 0x102;  // REFERENCE_ANGLE: last frame of a default-layout sample

int open_reading_end(int type, int& peer) {
  int fds[2] = {-1, -1};
  if (::socketpair(AF_UNIX, type | SOCK_CLOEXEC, 0, fds) != 0) {
    throw std::runtime_error(std::string("socketpair: ") + std::strerror(errno));
  }
  const int on = 1;
  ::setsockopt(fds[1], SOL_SOCKET, SO_TIMESTAMPNS, &on, sizeof on);  // what open() enables
  peer = fds[0];
  return fds[1];
}

/// Two socket pairs standing in for the waking and the quiet CAN_RAW socket.
struct SplitBus {
  int waking_peer = -1;
  int quiet_peer = -1;
  SplitWakeSource source;

  explicit SplitBus(int waking_type = SOCK_DGRAM)
      : source(SocketCanSource::adopt(open_reading_end(waking_type, waking_peer), "vcan0"),
               SocketCanSource::adopt(open_reading_end(SOCK_DGRAM, quiet_peer), "vcan0")) {
    source.set_read_timeout(30ms);
  }
  ~SplitBus() {
    if (waking_peer >= 0) ::close(waking_peer);
    if (quiet_peer >= 0) ::close(quiet_peer);
  }
  SplitBus(const SplitBus&) = delete;
  SplitBus& operator=(const SplitBus&) = delete;

  /// Sends like the kernel's filters route: the waking ID to one socket.
  void send(std::uint32_t id, std::uint8_t tag) {
    CanFrame f;
    f.id = id;
    f.len = 2;
    f.data[0] = tag;
    CanWireImage image{};
    const std::size_t size = encode_wire_frame(f, image);
    const int fd = id == kWakeId ? waking_peer : quiet_peer;
    ASSERT_EQ(::send(fd, image.data(), size, 0), static_cast<ssize_t>(size)) << std::strerror(errno);
  }
};

struct Got {
  std::uint32_t id;
  std::uint8_t tag;
};

Got read_frame(SplitWakeSource& source) {
  CanFrame f;
  const ReadStatus s = source.read(f);
  EXPECT_EQ(s, ReadStatus::kFrame);
  return Got{f.id, f.data[0]};
}

TEST(SplitWakeSource, FramesComeOutInTheOrderTheyArrived) {
  SplitBus bus;
  // 50 samples of the default layout; the waking frame is the last of each,
  // so it arrives after the sample's quiet frames.
  std::vector<Got> sent;
  for (int k = 0; k < 50; ++k) {
    const auto tag = static_cast<std::uint8_t>(k);
    for (std::uint32_t id : {0x100U, 0x101U, kWakeId}) {
      bus.send(id, tag);
      sent.push_back(Got{id, tag});
    }
    if (k % 10 == 9) {
      bus.send(0x1F0, tag);  // BENCH_INFO, quiet
      sent.push_back(Got{0x1F0, tag});
    }
  }
  for (std::size_t i = 0; i < sent.size(); ++i) {
    const Got g = read_frame(bus.source);
    ASSERT_EQ(g.id, sent[i].id) << "frame " << i;
    ASSERT_EQ(g.tag, sent[i].tag) << "frame " << i;
  }
  CanFrame f;
  EXPECT_EQ(bus.source.read(f), ReadStatus::kTimeout);
  EXPECT_EQ(bus.source.stats().frames, sent.size());
  EXPECT_EQ(bus.source.duplicates_skipped(), 0U);
}

TEST(SplitWakeSource, QuietFramesAfterTheLastWakingFrameWaitAtMostTheTimeout) {
  SplitBus bus;
  bus.send(0x100, 1);
  bus.send(kWakeId, 1);
  bus.send(0x100, 2);  // the next sample's first frame: nothing wakes the reader for it
  EXPECT_EQ(read_frame(bus.source).tag, 1);
  EXPECT_EQ(read_frame(bus.source).id, kWakeId);
  const auto start = std::chrono::steady_clock::now();
  const Got late = read_frame(bus.source);
  const auto waited = std::chrono::steady_clock::now() - start;
  EXPECT_EQ(late.id, 0x100U);
  EXPECT_EQ(late.tag, 2);
  EXPECT_GE(waited, 25ms) << "handed out before the read timeout: the reader was woken for a quiet frame";
  EXPECT_LT(waited, 1s);
}

TEST(SplitWakeSource, DrainedFramesComeBeforeTheDeviceIsReportedGone) {
  // A SOCK_SEQPACKET waking pair whose peer closes: kDeviceGone, after which
  // the caller drops the source. The quiet frames already received first.
  SplitBus bus(SOCK_SEQPACKET);
  bus.send(0x100, 7);
  bus.send(0x101, 7);
  ::close(bus.waking_peer);
  bus.waking_peer = -1;
  EXPECT_EQ(read_frame(bus.source).id, 0x100U);
  EXPECT_EQ(read_frame(bus.source).id, 0x101U);
  CanFrame f;
  EXPECT_EQ(bus.source.read(f), ReadStatus::kDeviceGone);
}

TEST(SplitWakeSource, FramesArrivingAfterTheDeviceWentAreNotAheadOfTheReport) {
  // Under a saturated bus the quiet socket refills as fast as it is read: the
  // status must come after what was queued when it came, not after an empty
  // queue (which may never be), or the waking socket overflows meanwhile.
  SplitBus bus(SOCK_SEQPACKET);
  bus.send(0x100, 1);
  bus.send(0x101, 1);
  ::close(bus.waking_peer);
  bus.waking_peer = -1;
  EXPECT_EQ(read_frame(bus.source).id, 0x100U);  // the status is read here and deferred
  bus.send(0x100, 2);                             // arrives after it
  EXPECT_EQ(read_frame(bus.source).id, 0x101U);
  CanFrame f;
  EXPECT_EQ(bus.source.read(f), ReadStatus::kDeviceGone);
  EXPECT_EQ(read_frame(bus.source).tag, 2) << "the later frame is still handed out, after the status";
}

TEST(SplitWakeSource, TruncatedQuietReadIsReportedAndCounted) {
  SplitBus bus;
  const std::array<std::uint8_t, 3> stub{1, 2, 3};
  ASSERT_EQ(::send(bus.quiet_peer, stub.data(), stub.size(), 0), 3);
  bus.send(kWakeId, 9);
  // The short read is found while draining for the waking frame and is
  // reported by the next call (a broken read has no place in the order).
  EXPECT_EQ(read_frame(bus.source).id, kWakeId);
  CanFrame f;
  EXPECT_EQ(bus.source.read(f), ReadStatus::kTruncated);
  EXPECT_EQ(bus.source.stats().truncated, 1U);
  EXPECT_EQ(bus.source.stats().frames, 1U);
}

TEST(SplitWakeSource, WithoutAQuietSocketEveryFrameWakes) {
  int peer = -1;
  SplitWakeSource source(SocketCanSource::adopt(open_reading_end(SOCK_DGRAM, peer), "vcan0"), std::nullopt);
  source.set_read_timeout(30ms);
  EXPECT_FALSE(source.split());
  CanFrame f;
  f.id = 0x100;
  f.len = 1;
  CanWireImage image{};
  const std::size_t size = encode_wire_frame(f, image);
  ASSERT_EQ(::send(peer, image.data(), size, 0), static_cast<ssize_t>(size));
  CanFrame got;
  EXPECT_EQ(source.read(got), ReadStatus::kFrame);
  EXPECT_EQ(got.id, 0x100U);
  EXPECT_EQ(source.read(got), ReadStatus::kTimeout);
  ::close(peer);
}

TEST(SplitWakeSource, QuietFramesFlowWithoutWaitingOnceNoWakingFrameComes) {
  // Wrong wake IDs (nothing wakes the reader): after one read timeout the
  // quiet frames are handed out as they come, not one per timeout.
  SplitBus bus;
  for (int i = 0; i < 20; ++i) bus.send(0x100, static_cast<std::uint8_t>(i));
  const auto start = std::chrono::steady_clock::now();
  for (int i = 0; i < 20; ++i) EXPECT_EQ(read_frame(bus.source).tag, i);
  EXPECT_LT(std::chrono::steady_clock::now() - start, 25ms * 3) << "waited a timeout per frame";
  EXPECT_EQ(bus.source.waking_silences(), 1U);
  bus.send(kWakeId, 20);  // a waking frame still comes out in order
  bus.send(0x100, 21);
  EXPECT_EQ(read_frame(bus.source).id, kWakeId);
  EXPECT_EQ(read_frame(bus.source).tag, 21);
}

TEST(SplitWakeSource, ChangingTheSplitNeedsASourceFromOpen) {
  SplitBus bus;
  EXPECT_TRUE(bus.source.split());
  EXPECT_THROW(bus.source.set_wake({}), std::logic_error);
}

TEST(SplitWakeSource, OpenRefusesFiltersTogetherWithWakeIds) {
  SocketCanOptions options;
  options.iface = "vcan0";
  options.filters.push_back(CanIdFilter{0x100, 0x7FF});
  try {
    (void)SplitWakeSource::open(options, {CanIdFilter{kWakeId, 0x7FF}});
    FAIL() << "expected SocketCanError";
  } catch (const SocketCanError& e) {
    EXPECT_EQ(e.error_code(), EINVAL);
    EXPECT_NE(std::string(e.what()).find("vcan0"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace resolver
