// Wire images: CanFrame <-> struct can_frame / canfd_frame bytes.
// Reference images are built here from the kernel structs themselves, so a
// layout mistake in can_wire.cpp cannot hide behind a shared helper.
#include <linux/can.h>
#include <linux/can/error.h>

#include <cstring>
#include <random>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

#include "drivers/socketcan/can_filter.h"
#include "drivers/socketcan/can_wire.h"

namespace resolver {
namespace {

std::vector<std::uint8_t> image_of(const can_frame& raw) {
  std::vector<std::uint8_t> out(sizeof raw);
  std::memcpy(out.data(), &raw, sizeof raw);
  return out;
}
std::vector<std::uint8_t> image_of(const canfd_frame& raw) {
  std::vector<std::uint8_t> out(sizeof raw);
  std::memcpy(out.data(), &raw, sizeof raw);
  return out;
}

void expect_same_frame(const CanFrame& a, const CanFrame& b) {
  EXPECT_EQ(a.id, b.id);
  EXPECT_EQ(a.extended, b.extended);
  EXPECT_EQ(a.rtr, b.rtr);
  EXPECT_EQ(a.error, b.error);
  EXPECT_EQ(a.fd, b.fd);
  EXPECT_EQ(a.fd_flags, b.fd_flags);
  EXPECT_EQ(a.len, b.len);
  EXPECT_EQ(a.data, b.data);
}

TEST(SocketCanWire, MtuConstantsMatchKernelStructs) {
  EXPECT_EQ(kCanMtu, sizeof(can_frame));
  EXPECT_EQ(kCanFdMtu, sizeof(canfd_frame));
}

TEST(SocketCanWire, DecodesClassicStandardFrame) {
  can_frame raw{};
  raw.can_id = 0x100;
  raw.len = 8;
  for (std::uint8_t i = 0; i < 8; ++i) raw.data[i] = static_cast<std::uint8_t>(0xA0 + i);
  CanFrame frame;
  frame.timestamp_us = 42;
  frame.set_iface("keep");
  ASSERT_EQ(decode_wire_frame(image_of(raw), frame), WireDecodeStatus::kOk);
  EXPECT_EQ(frame.id, 0x100U);
  EXPECT_FALSE(frame.extended);
  EXPECT_FALSE(frame.rtr);
  EXPECT_FALSE(frame.error);
  EXPECT_FALSE(frame.fd);
  EXPECT_EQ(frame.len, 8);
  for (std::size_t i = 0; i < 8; ++i) EXPECT_EQ(frame.data[i], raw.data[i]) << i;
  EXPECT_EQ(frame.timestamp_us, 42) << "decode must not touch the timestamp";
  EXPECT_EQ(frame.iface_name(), "keep") << "decode must not touch the interface";
}

TEST(SocketCanWire, DecodesExtendedFrameAndZeroesDataBeyondLen) {
  can_frame raw{};
  raw.can_id = 0x18FF50E5U | CAN_EFF_FLAG;
  raw.len = 3;
  raw.data[0] = 1;
  raw.data[1] = 2;
  raw.data[2] = 3;
  raw.data[5] = 0x77;  // garbage past len must not leak into the frame
  CanFrame frame;
  frame.data.fill(0xEE);
  ASSERT_EQ(decode_wire_frame(image_of(raw), frame), WireDecodeStatus::kOk);
  EXPECT_TRUE(frame.extended);
  EXPECT_EQ(frame.id, 0x18FF50E5U);
  EXPECT_EQ(frame.len, 3);
  EXPECT_EQ(frame.data[2], 3);
  EXPECT_EQ(frame.data[5], 0);
  EXPECT_EQ(frame.data[63], 0);
}

TEST(SocketCanWire, DecodesRemoteFrameWithoutPayload) {
  can_frame raw{};
  raw.can_id = 0x123U | CAN_RTR_FLAG;
  raw.len = 4;  // requested DLC
  raw.data[0] = 0x55;
  CanFrame frame;
  ASSERT_EQ(decode_wire_frame(image_of(raw), frame), WireDecodeStatus::kOk);
  EXPECT_TRUE(frame.rtr);
  EXPECT_EQ(frame.id, 0x123U);
  EXPECT_EQ(frame.len, 4);
  EXPECT_EQ(frame.data[0], 0);
}

TEST(SocketCanWire, DecodesFdFrameKeepingBrsAndEsiOnly) {
  canfd_frame raw{};
  raw.can_id = 0x1F0;
  raw.len = 64;
  raw.flags = CANFD_BRS | CANFD_ESI | CANFD_FDF;
  for (std::size_t i = 0; i < 64; ++i) raw.data[i] = static_cast<std::uint8_t>(i * 3);
  CanFrame frame;
  ASSERT_EQ(decode_wire_frame(image_of(raw), frame), WireDecodeStatus::kOk);
  EXPECT_TRUE(frame.fd);
  EXPECT_EQ(frame.fd_flags, CANFD_BRS | CANFD_ESI);
  EXPECT_EQ(frame.len, 64);
  EXPECT_EQ(frame.data[63], static_cast<std::uint8_t>(63 * 3));
}

TEST(SocketCanWire, DecodesErrorFrameClassBitsAsId) {
  can_frame raw{};
  raw.can_id = CAN_ERR_FLAG | CAN_ERR_CRTL | CAN_ERR_BUSOFF;
  raw.len = CAN_ERR_DLC;
  raw.data[1] = CAN_ERR_CRTL_RX_PASSIVE;
  CanFrame frame;
  ASSERT_EQ(decode_wire_frame(image_of(raw), frame), WireDecodeStatus::kOk);
  EXPECT_TRUE(frame.error);
  EXPECT_FALSE(frame.extended);
  EXPECT_EQ(frame.id, CAN_ERR_CRTL | CAN_ERR_BUSOFF);
  EXPECT_EQ(frame.data[1], CAN_ERR_CRTL_RX_PASSIVE);
}

TEST(SocketCanWire, RejectsWrongSizesWithoutTouchingFrame) {
  CanFrame frame;
  frame.id = 0x7;
  frame.len = 2;
  for (const std::size_t size : {std::size_t{0}, std::size_t{8}, kCanMtu - 1, kCanMtu + 1,
                                 kCanFdMtu - 1, std::size_t{80}}) {
    const std::vector<std::uint8_t> image(size, 0xFF);
    EXPECT_EQ(decode_wire_frame(image, frame), WireDecodeStatus::kBadSize) << size;
    EXPECT_EQ(frame.id, 0x7U);
    EXPECT_EQ(frame.len, 2);
  }
}

TEST(SocketCanWire, RejectsLengthBeyondFrameKind) {
  can_frame classic{};
  classic.len = 9;
  canfd_frame fd{};
  fd.len = 65;
  CanFrame frame;
  EXPECT_EQ(decode_wire_frame(image_of(classic), frame), WireDecodeStatus::kBadLength);
  EXPECT_EQ(decode_wire_frame(image_of(fd), frame), WireDecodeStatus::kBadLength);
}

TEST(SocketCanWire, EncodesClassicFrameExactlyLikeKernelStruct) {
  CanFrame frame;
  frame.id = 0x101;
  frame.len = 8;
  for (std::uint8_t i = 0; i < 8; ++i) frame.data[i] = static_cast<std::uint8_t>(0x10 + i);
  CanWireImage image{};
  ASSERT_EQ(encode_wire_frame(frame, image), kCanMtu);

  can_frame expected{};
  expected.can_id = 0x101;
  expected.len = 8;
  for (std::uint8_t i = 0; i < 8; ++i) expected.data[i] = static_cast<std::uint8_t>(0x10 + i);
  EXPECT_EQ(std::memcmp(image.data(), &expected, sizeof expected), 0);
}

TEST(SocketCanWire, EncodesFdExtendedFrameExactlyLikeKernelStruct) {
  CanFrame frame;
  frame.id = 0x1ABCDEF;
  frame.extended = true;
  frame.fd = true;
  frame.fd_flags = CANFD_BRS;
  frame.len = 12;
  frame.data[11] = 0x99;
  CanWireImage image{};
  ASSERT_EQ(encode_wire_frame(frame, image), kCanFdMtu);

  canfd_frame expected{};
  expected.can_id = 0x1ABCDEFU | CAN_EFF_FLAG;
  expected.len = 12;
  expected.flags = CANFD_BRS;
  expected.data[11] = 0x99;
  EXPECT_EQ(std::memcmp(image.data(), &expected, sizeof expected), 0);
}

TEST(SocketCanWire, EncodeRejectsFramesTheKernelWouldRefuse) {
  CanWireImage image{};
  CanFrame too_wide_std;
  too_wide_std.id = 0x800;
  EXPECT_THROW(encode_wire_frame(too_wide_std, image), std::invalid_argument);

  CanFrame too_wide_ext;
  too_wide_ext.extended = true;
  too_wide_ext.id = 0x20000000;
  EXPECT_THROW(encode_wire_frame(too_wide_ext, image), std::invalid_argument);

  CanFrame long_classic;
  long_classic.len = 9;
  EXPECT_THROW(encode_wire_frame(long_classic, image), std::invalid_argument);

  CanFrame long_fd;
  long_fd.fd = true;
  long_fd.len = 65;
  EXPECT_THROW(encode_wire_frame(long_fd, image), std::invalid_argument);

  CanFrame remote_fd;
  remote_fd.fd = true;
  remote_fd.rtr = true;
  EXPECT_THROW(encode_wire_frame(remote_fd, image), std::invalid_argument);

  CanFrame bad_flags;
  bad_flags.fd = true;
  bad_flags.fd_flags = CANFD_FDF;
  EXPECT_THROW(encode_wire_frame(bad_flags, image), std::invalid_argument);
}

TEST(SocketCanWire, MessageNamesTheOffendingId) {
  CanWireImage image{};
  CanFrame frame;
  frame.id = 0x800;
  try {
    (void)encode_wire_frame(frame, image);
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("0x800"), std::string::npos) << e.what();
  }
}

// Property test (libcanard style): any valid frame survives encode -> decode.
TEST(SocketCanWire, RandomFramesRoundTrip) {
  std::mt19937 rng(20240601);  // fixed seed: failures are reproducible
  auto pick = [&rng](std::uint32_t lo, std::uint32_t hi) {
    return std::uniform_int_distribution<std::uint32_t>(lo, hi)(rng);
  };
  for (int trial = 0; trial < 5000; ++trial) {
    CanFrame in;
    const std::uint32_t kind = pick(0, 3);  // 0 classic, 1 remote, 2 FD, 3 error
    in.extended = kind != 3 && pick(0, 1) == 1;
    in.id = pick(0, in.extended ? 0x1FFFFFFFU : 0x7FFU);
    if (kind == 3) {
      in.error = true;
      in.id = pick(0, CAN_ERR_MASK);
    }
    in.rtr = kind == 1;
    in.fd = kind == 2;
    in.fd_flags = in.fd ? static_cast<std::uint8_t>(pick(0, 3)) : std::uint8_t{0};
    in.len = static_cast<std::uint8_t>(pick(0, in.fd ? 64 : 8));
    if (!in.rtr) {
      for (std::size_t i = 0; i < in.len; ++i) in.data[i] = static_cast<std::uint8_t>(pick(0, 255));
    }
    CanWireImage image{};
    const std::size_t size = encode_wire_frame(in, image);
    ASSERT_EQ(size, in.fd ? kCanFdMtu : kCanMtu);
    CanFrame out;
    out.data.fill(0xCD);
    ASSERT_EQ(decode_wire_frame(std::span<const std::uint8_t>(image.data(), size), out),
              WireDecodeStatus::kOk)
        << "trial " << trial;
    SCOPED_TRACE(trial);
    expect_same_frame(in, out);
  }
}

// The kernel's rule (can.rst): <received_can_id> & mask == can_id & mask.
bool kernel_accepts(const KernelCanFilter& f, std::uint32_t received_can_id) {
  return (received_can_id & f.can_mask) == (f.can_id & f.can_mask);
}

TEST(SocketCanFilter, StandardFilterSelectsFrameFormat) {
  const KernelCanFilter f = to_kernel_filter({0x100, 0x7F0});
  EXPECT_TRUE(kernel_accepts(f, 0x100));
  EXPECT_TRUE(kernel_accepts(f, 0x10F));
  EXPECT_TRUE(kernel_accepts(f, 0x100 | CAN_RTR_FLAG)) << "remote frames pass too";
  EXPECT_FALSE(kernel_accepts(f, 0x110));
  EXPECT_FALSE(kernel_accepts(f, 0x100 | CAN_EFF_FLAG)) << "extended frame with same low bits";
}

TEST(SocketCanFilter, ExtendedFilterMatchesOnlyExtendedFrames) {
  const KernelCanFilter f = to_kernel_filter({0x18FF50E5, 0x1FFFFFFF, true});
  EXPECT_TRUE(kernel_accepts(f, 0x18FF50E5U | CAN_EFF_FLAG));
  EXPECT_FALSE(kernel_accepts(f, 0x18FF50E5U & CAN_SFF_MASK));
  EXPECT_FALSE(kernel_accepts(f, 0x18FF50E4U | CAN_EFF_FLAG));
}

TEST(SocketCanFilter, RejectsIdsWiderThanTheirFormat) {
  EXPECT_THROW((void)to_kernel_filter({0x800, 0x7FF}), std::invalid_argument);
  EXPECT_THROW((void)to_kernel_filter({0x20000000, 0x1FFFFFFF, true}), std::invalid_argument);
  EXPECT_NO_THROW((void)to_kernel_filter({0x800, 0x7FF, true}));
}

}  // namespace
}  // namespace resolver
