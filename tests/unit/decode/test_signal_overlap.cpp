// Overlapping DBC signals (issue 16): a signal the decoder reads that shares
// bits with another signal of its message is an error naming both, the message
// and the bits; an overlap among signals it does not read is only a warning.
// Bit sets are checked against hand-counted DBC bit numbers, for Intel and for
// Motorola (sawtooth) signals.
#include <gtest/gtest.h>

#include <memory>
#include <stdexcept>
#include <string>

#include "daemon/dbc/dbc_parser.h"
#include "daemon/decode/frame_decoder.h"

namespace resolver {
namespace {

std::shared_ptr<const dbc::Database> parse(const std::string& signals) {
  const std::string text = "VERSION \"\"\nBU_: INV RD\nBO_ 256 FB: 8 INV\n SG_ counter : 0|8@1+ (1,0) [0|255] \"\" RD\n" +
                           signals + "\n";
  try {
    return std::make_shared<const dbc::Database>(dbc::parse_dbc(text, "test.dbc"));
  } catch (const InputError& e) {
    ADD_FAILURE() << e.what();
    return nullptr;
  }
}

SignalMap sincos_map() {
  SignalMap m;
  m.roles[static_cast<std::size_t>(Role::kSin)] = SignalRef{"FB", "s"};
  m.roles[static_cast<std::size_t>(Role::kCos)] = SignalRef{"FB", "c"};
  m.crc_signal = "";
  m.crc = CrcAlgorithm::kNone;
  m.bench_info_message = "";
  return m;
}

std::string construction_error(const std::string& signals) {
  try {
    FrameDecoder d(parse(signals), sincos_map());
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(SignalOverlap, CosOverSinIsAnErrorNamingBothAndTheBits) {
  const std::string err = construction_error(" SG_ s : 8|16@1- (1,0) [-32768|32767] \"\" RD\n"
                                             " SG_ c : 16|16@1- (1,0) [-32768|32767] \"\" RD");
  EXPECT_NE(err.find("message 'FB': signals 's' (bits 8..23) and 'c' (bits 16..31) overlap in bits 16..23"),
            std::string::npos)
      << err;
}

TEST(SignalOverlap, CounterIsReadToo) {
  const std::string err = construction_error(" SG_ s : 4|16@1- (1,0) [-32768|32767] \"\" RD\n"
                                             " SG_ c : 24|16@1- (1,0) [-32768|32767] \"\" RD");
  EXPECT_NE(err.find("'counter' (bits 0..7) and 's' (bits 4..19) overlap in bits 4..7"), std::string::npos) << err;
}

TEST(SignalOverlap, MotorolaBitsAreTheSawtooth) {
  // Motorola s: start bit 15 (MSB of byte 1), 16 bits -> bytes 1..2 = DBC bits 8..23.
  // Motorola c: start bit 23 (MSB of byte 2), 12 bits -> all of byte 2 and the top
  // nibble of byte 3 (bits 28..31): overlap = byte 2 = bits 16..23.
  const std::string err = construction_error(" SG_ s : 15|16@0- (1,0) [-32768|32767] \"\" RD\n"
                                             " SG_ c : 23|12@0- (1,0) [-2048|2047] \"\" RD");
  EXPECT_NE(err.find("'s' (bits 8..23) and 'c' (bits 16..23, 28..31) overlap in bits 16..23"), std::string::npos)
      << err;
}

TEST(SignalOverlap, AdjacentSignalsAndMultiplexedAlternativesAreFine) {
  EXPECT_EQ(construction_error(" SG_ s : 8|16@1- (1,0) [-32768|32767] \"\" RD\n"
                               " SG_ c : 24|16@1- (1,0) [-32768|32767] \"\" RD"),
            "");
  // Two views of bytes 5..6 behind different multiplexor values never share a frame.
  const auto db = parse(" SG_ s : 8|16@1- (1,0) [-32768|32767] \"\" RD\n"
                        " SG_ c : 24|16@1- (1,0) [-32768|32767] \"\" RD\n"
                        " SG_ mux M : 56|8@1+ (1,0) [0|255] \"\" RD\n"
                        " SG_ a m1 : 40|16@1+ (1,0) [0|0] \"\" RD\n"
                        " SG_ b m2 : 40|8@1+ (1,0) [0|0] \"\" RD");
  const FrameDecoder d(db, sincos_map());
  EXPECT_TRUE(d.warnings().empty());
}

TEST(SignalOverlap, UnreadSignalsOverlappingIsAWarning) {
  const auto db = parse(" SG_ s : 8|16@1- (1,0) [-32768|32767] \"\" RD\n"
                        " SG_ c : 24|16@1- (1,0) [-32768|32767] \"\" RD\n"
                        " SG_ word : 40|16@1+ (1,0) [0|0] \"\" RD\n"
                        " SG_ low : 40|8@1+ (1,0) [0|0] \"\" RD");
  const FrameDecoder d(db, sincos_map());
  ASSERT_EQ(d.warnings().size(), 1U);
  EXPECT_NE(d.warnings()[0].find("'word' (bits 40..55) and 'low' (bits 40..47) overlap in bits 40..47"),
            std::string::npos)
      << d.warnings()[0];
}

}  // namespace
}  // namespace resolver
