// Error-frame classes and descriptions, one class bit at a time, then combined.
#include <linux/can.h>
#include <linux/can/error.h>

#include <set>
#include <string>

#include <gtest/gtest.h>

#include "drivers/socketcan/can_error_frame.h"

namespace resolver {
namespace {

CanFrame error_frame(std::uint32_t class_bits) {
  CanFrame frame;
  frame.error = true;
  frame.id = class_bits;
  frame.len = CAN_ERR_DLC;
  return frame;
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

struct ClassCase {
  CanErrorClass error_class;
  std::uint32_t kernel_bit;
  const char* counter_name;
  const char* phrase;  // must appear in the description
};

class SocketCanErrorClass : public ::testing::TestWithParam<ClassCase> {};

TEST_P(SocketCanErrorClass, SingleBitGivesExactlyThatClass) {
  const ClassCase& c = GetParam();
  EXPECT_EQ(error_class_mask(c.error_class), c.kernel_bit);
  EXPECT_EQ(error_class_name(c.error_class), c.counter_name);
  const CanFrame frame = error_frame(c.kernel_bit);
  const CanErrorClassSet set = error_classes(frame);
  EXPECT_EQ(set.count(), 1U);
  EXPECT_TRUE(has_error_class(set, c.error_class));
  const std::string text = describe_error_frame(frame);
  EXPECT_TRUE(contains(text, c.phrase)) << text;
  EXPECT_FALSE(contains(text, ";")) << "one class, one part: " << text;
}

INSTANTIATE_TEST_SUITE_P(
    AllClasses, SocketCanErrorClass,
    ::testing::Values(
        ClassCase{CanErrorClass::kTxTimeout, CAN_ERR_TX_TIMEOUT, "tx_timeout", "tx timeout"},
        ClassCase{CanErrorClass::kLostArbitration, CAN_ERR_LOSTARB, "lost_arbitration",
                  "lost arbitration"},
        ClassCase{CanErrorClass::kController, CAN_ERR_CRTL, "controller", "controller problem"},
        ClassCase{CanErrorClass::kProtocol, CAN_ERR_PROT, "protocol", "protocol violation"},
        ClassCase{CanErrorClass::kTransceiver, CAN_ERR_TRX, "transceiver", "transceiver"},
        ClassCase{CanErrorClass::kAck, CAN_ERR_ACK, "ack", "ack error"},
        ClassCase{CanErrorClass::kBusOff, CAN_ERR_BUSOFF, "bus_off", "bus-off"},
        ClassCase{CanErrorClass::kBusError, CAN_ERR_BUSERROR, "bus_error", "bus error"},
        ClassCase{CanErrorClass::kRestarted, CAN_ERR_RESTARTED, "restarted", "restarted"}),
    [](const ::testing::TestParamInfo<ClassCase>& param_info) {
      return std::string(error_class_name(param_info.param.error_class));
    });

TEST(SocketCanErrorFrame, ClassNamesAndMasksAreDistinct) {
  std::set<std::string_view> names;
  std::uint32_t all_bits = 0;
  for (const CanErrorClass c : kAllCanErrorClasses) {
    names.insert(error_class_name(c));
    EXPECT_EQ(all_bits & error_class_mask(c), 0U) << error_class_name(c);
    all_bits |= error_class_mask(c);
  }
  EXPECT_EQ(names.size(), kCanErrorClassCount);
}

TEST(SocketCanErrorFrame, ControllerDetails) {
  CanFrame frame = error_frame(CAN_ERR_CRTL);
  frame.data[1] = CAN_ERR_CRTL_RX_OVERFLOW | CAN_ERR_CRTL_TX_PASSIVE;
  const std::string text = describe_error_frame(frame);
  EXPECT_TRUE(contains(text, "controller problem: rx overflow, tx error passive")) << text;

  frame.data[1] = CAN_ERR_CRTL_UNSPEC;
  EXPECT_TRUE(contains(describe_error_frame(frame), "unspecified"));
}

TEST(SocketCanErrorFrame, ProtocolTypeAndLocation) {
  CanFrame frame = error_frame(CAN_ERR_PROT);
  frame.data[2] = CAN_ERR_PROT_STUFF | CAN_ERR_PROT_TX;
  frame.data[3] = CAN_ERR_PROT_LOC_DATA;
  const std::string text = describe_error_frame(frame);
  EXPECT_TRUE(contains(text, "bit stuffing error")) << text;
  EXPECT_TRUE(contains(text, "on transmission")) << text;
  EXPECT_TRUE(contains(text, "at data field")) << text;

  frame.data[3] = CAN_ERR_PROT_LOC_ACK;
  EXPECT_TRUE(contains(describe_error_frame(frame), "at ACK slot"));
}

TEST(SocketCanErrorFrame, LostArbitrationBit) {
  CanFrame frame = error_frame(CAN_ERR_LOSTARB);
  frame.data[0] = 5;
  EXPECT_TRUE(contains(describe_error_frame(frame), "at bit 5"));
  frame.data[0] = CAN_ERR_LOSTARB_UNSPEC;
  EXPECT_TRUE(contains(describe_error_frame(frame), "unspecified"));
}

TEST(SocketCanErrorFrame, TransceiverWiring) {
  CanFrame frame = error_frame(CAN_ERR_TRX);
  frame.data[4] = CAN_ERR_TRX_CANH_NO_WIRE | CAN_ERR_TRX_CANL_SHORT_TO_GND;
  const std::string text = describe_error_frame(frame);
  EXPECT_TRUE(contains(text, "CANH no wire")) << text;
  EXPECT_TRUE(contains(text, "CANL short to ground")) << text;
}

TEST(SocketCanErrorFrame, CombinedClassesAreAllReported) {
  CanFrame frame = error_frame(CAN_ERR_CRTL | CAN_ERR_BUSOFF | CAN_ERR_RESTARTED);
  frame.data[1] = CAN_ERR_CRTL_RX_PASSIVE;
  const CanErrorClassSet set = error_classes(frame);
  EXPECT_EQ(set.count(), 3U);
  EXPECT_TRUE(has_error_class(set, CanErrorClass::kController));
  EXPECT_TRUE(has_error_class(set, CanErrorClass::kBusOff));
  EXPECT_TRUE(has_error_class(set, CanErrorClass::kRestarted));
  const std::string text = describe_error_frame(frame);
  EXPECT_TRUE(contains(text, "controller problem: rx error passive; ")) << text;
  EXPECT_TRUE(contains(text, "bus-off")) << text;
  EXPECT_TRUE(contains(text, "restarted")) << text;
}

TEST(SocketCanErrorFrame, ErrorCountersOnlyWhenFlagged) {
  CanFrame frame = error_frame(CAN_ERR_CRTL);
  frame.data[1] = CAN_ERR_CRTL_RX_PASSIVE;
  frame.data[6] = 3;
  frame.data[7] = 130;
  EXPECT_FALSE(error_counters(frame).has_value());

  frame.id |= CAN_ERR_CNT;
  const auto counters = error_counters(frame);
  ASSERT_TRUE(counters.has_value());
  EXPECT_EQ(counters->tx, 3);
  EXPECT_EQ(counters->rx, 130);
  EXPECT_TRUE(contains(describe_error_frame(frame), "error counters tx=3 rx=130"));
  EXPECT_EQ(error_classes(frame).count(), 1U) << "CNT is information, not a class";
}

TEST(SocketCanErrorFrame, UnknownClassBitsAreShownNotHidden) {
  const CanFrame frame = error_frame(0x10000000U);
  EXPECT_TRUE(error_classes(frame).none());
  EXPECT_TRUE(contains(describe_error_frame(frame), "unknown error class bits 0x10000000"));
}

TEST(SocketCanErrorFrame, DataFrameIsNotAnErrorFrame) {
  CanFrame frame;
  frame.id = CAN_ERR_BUSOFF;  // same bits, but no error flag
  EXPECT_TRUE(error_classes(frame).none());
  EXPECT_EQ(describe_error_frame(frame), "not an error frame");
  EXPECT_FALSE(error_counters(frame).has_value());
}

}  // namespace
}  // namespace resolver
