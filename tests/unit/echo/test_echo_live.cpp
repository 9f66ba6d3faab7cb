// Live mode on memq:// (in-process LCM): count, timeout, filters, and a
// failing sink that must not unwind through LCM's C code.
#include <gtest/gtest.h>

#include <stdexcept>

#include <lcm/lcm-cpp.hpp>
#include <resolver/angle_t.hpp>

#include "json_test_parser.h"
#include "tools/echo/live_echo.h"

namespace resolver {
namespace {

using echo_test_support::parse_json;
using namespace std::chrono_literals;

class EchoLive : public ::testing::Test {
 protected:
  EchoLive() : lcm_("memq://"), registry_(LcmTypeRegistry::with_embedded_types()), decoder_(registry_) {}

  void publish(int n, const std::string& channel = "RESOLVER_ANGLE") {
    for (int i = 0; i < n; ++i) {
      resolver::angle_t a{};
      a.utime = 100 + i;
      lcm_.publish(channel, &a);
    }
  }

  lcm::LCM lcm_;
  LcmTypeRegistry registry_;
  LcmJsonDecoder decoder_;
  std::vector<std::string> lines_;
  JsonLineSink sink_ = [this](const std::string& l) { lines_.push_back(l); };
};

TEST_F(EchoLive, StopsAfterCount) {
  ASSERT_TRUE(lcm_.good());
  LiveEcho live(lcm_, decoder_, EchoFilter{}, sink_);
  publish(3);
  const auto r = live.run(2, 5s);
  EXPECT_FALSE(r.timed_out);
  EXPECT_EQ(r.emitted, 2);
  ASSERT_EQ(lines_.size(), 2u);
  EXPECT_EQ(parse_json(lines_[1])["utime"].integer(), 101);
  // The third message is still queued; a second run picks it up.
  const auto again = live.run(1, 5s);
  EXPECT_EQ(again.emitted, 1);
  EXPECT_EQ(parse_json(lines_.at(2))["utime"].integer(), 102);
}

TEST_F(EchoLive, StopsAtTimeoutWithWhatArrived) {
  const EchoFilter filter = make_echo_filter("RESOLVER_.*", "");
  LiveEcho live(lcm_, decoder_, filter, sink_);
  publish(1);
  publish(1, "OTHER_ANGLE");
  const auto r = live.run(5, 200ms);
  EXPECT_TRUE(r.timed_out);
  EXPECT_EQ(r.emitted, 1);
  EXPECT_EQ(lines_.size(), 1u);
}

TEST_F(EchoLive, SinkExceptionIsThrownAsIoErrorOnceLcmHasReturned) {
  const JsonLineSink throwing = [](const std::string&) { throw std::runtime_error("disk full"); };
  LiveEcho live(lcm_, decoder_, EchoFilter{}, throwing);
  publish(2);
  try {
    (void)live.run(2, 2s, Where::at_option("--lcm memq://"));
    ADD_FAILURE() << "expected IoError";
  } catch (const IoError& e) {  // exit 3
    const std::string what = e.what();
    EXPECT_EQ(what.rfind("--lcm memq://: channel '", 0), 0U) << what;
    EXPECT_NE(what.find("disk full"), std::string::npos) << what;
    EXPECT_NE(what.find("RESOLVER_ANGLE"), std::string::npos) << what;
  }
}

}  // namespace
}  // namespace resolver
