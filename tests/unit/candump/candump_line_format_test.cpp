// append_candump_line / check_loggable: the exact bytes candump -l writes, and
// the frames a log cannot hold.
#include <gtest/gtest.h>

#include <string>

#include "drivers/candump/candump_line.h"

namespace resolver {
namespace {

CanFrame frame_at(std::int64_t t_us, std::uint32_t id) {
  CanFrame f;
  f.timestamp_us = t_us;
  f.id = id;
  f.set_iface("can0");
  return f;
}

std::string line_of(const CanFrame& f) {
  std::string out;
  append_candump_line(f, out);
  return out;
}

// The expected strings follow can-utils: "(%010lu.%06lu) %s %s\n", ids as
// %03X / %08X, data as %02X per byte, "R%d" only for a non-zero RTR length,
// "##%X" + data for CAN FD.
TEST(CandumpLineFormat, MatchesCandumpLayout) {
  CanFrame f = frame_at(1699999999123456, 0x123);
  f.len = 4;
  f.data = {0xDE, 0xAD, 0xBE, 0xEF};
  EXPECT_EQ(line_of(f), "(1699999999.123456) can0 123#DEADBEEF\n");

  CanFrame early = frame_at(166000042, 0x00A);  // seconds zero-padded to 10 digits
  EXPECT_EQ(line_of(early), "(0000000166.000042) can0 00A#\n");

  CanFrame ext = frame_at(1, 0x1ABCDEF0);
  ext.extended = true;
  ext.len = 1;
  ext.data[0] = 0x07;
  EXPECT_EQ(line_of(ext), "(0000000000.000001) can0 1ABCDEF0#07\n");

  CanFrame rtr = frame_at(0, 0x7FF);
  rtr.rtr = true;
  EXPECT_EQ(line_of(rtr), "(0000000000.000000) can0 7FF#R\n");
  rtr.len = 5;
  EXPECT_EQ(line_of(rtr), "(0000000000.000000) can0 7FF#R5\n");

  CanFrame fd = frame_at(0, 0x123);
  fd.fd = true;
  fd.fd_flags = 0x03;
  fd.len = 2;
  fd.data[0] = 0xAA;
  fd.data[1] = 0x0B;
  EXPECT_EQ(line_of(fd), "(0000000000.000000) can0 123##3AA0B\n");

  CanFrame err = frame_at(0, 0x004);  // CAN_ERR_CRTL
  err.error = true;
  err.len = 8;
  err.data[1] = 0x04;
  EXPECT_EQ(line_of(err), "(0000000000.000000) can0 20000004#0004000000000000\n");
}

TEST(CandumpLineFormat, AppendsWithoutTouchingWhatIsThere) {
  std::string out = "keep\n";
  append_candump_line(frame_at(2000000, 0x001), out);
  append_candump_line(frame_at(3000000, 0x002), out);
  EXPECT_EQ(out, "keep\n(0000000002.000000) can0 001#\n(0000000003.000000) can0 002#\n");
}

TEST(CandumpLineFormat, FormattedLineParsesBack) {
  CanFrame f = frame_at(1234567890987654, 0x1FFFFFFF);
  f.extended = true;
  f.fd = true;
  f.fd_flags = 0x02;
  f.len = 48;
  for (std::size_t i = 0; i < f.len; ++i) f.data[i] = static_cast<std::uint8_t>(i * 37U);
  CanFrame back;
  const auto problem = parse_candump_line(line_of(f), back);
  ASSERT_FALSE(problem.has_value()) << problem->message;
  EXPECT_EQ(back.timestamp_us, f.timestamp_us);
  EXPECT_EQ(back.id, f.id);
  EXPECT_TRUE(back.extended && back.fd);
  EXPECT_EQ(back.fd_flags, f.fd_flags);
  EXPECT_EQ(back.len, f.len);
  EXPECT_EQ(back.data, f.data);
}

TEST(CandumpLineFormat, CheckLoggableRejectsWhatALogCannotHold) {
  EXPECT_NO_THROW(check_loggable(frame_at(0, 0x7FF)));

  auto rejects = [](CanFrame f, const std::string& phrase) {
    try {
      check_loggable(f, Where::at_file("out.log", 7));
      ADD_FAILURE() << "not refused: " << phrase;
    } catch (const InputError& e) {
      const std::string why = e.what();
      EXPECT_EQ(why.rfind("out.log:7: cannot log this frame: ", 0), 0U) << why;
      EXPECT_NE(why.find(phrase), std::string::npos) << why;
    }
  };
  rejects(frame_at(-1, 0x1), "negative");
  rejects(frame_at(0, 0x800), "exceeds");
  CanFrame ext = frame_at(0, 0x20000000);
  ext.extended = true;
  rejects(ext, "exceeds");
  CanFrame no_iface = frame_at(0, 0x1);
  no_iface.set_iface("");
  rejects(no_iface, "interface name is empty");
  CanFrame blank_iface = frame_at(0, 0x1);
  blank_iface.set_iface("can 0");
  rejects(blank_iface, "blank");
  CanFrame classic9 = frame_at(0, 0x1);
  classic9.len = 9;
  rejects(classic9, "exceeds 8");
  CanFrame fd10 = frame_at(0, 0x1);
  fd10.fd = true;
  fd10.len = 10;
  rejects(fd10, "not one of");
  CanFrame fd_rtr = frame_at(0, 0x1);
  fd_rtr.fd = true;
  fd_rtr.rtr = true;
  rejects(fd_rtr, "no remote frames");
  CanFrame err_fd = frame_at(0, 0x1);
  err_fd.error = true;
  err_fd.fd = true;
  rejects(err_fd, "error frames cannot");
  CanFrame classic_flags = frame_at(0, 0x1);
  classic_flags.fd_flags = 1;
  rejects(classic_flags, "classic");
}

}  // namespace
}  // namespace resolver
