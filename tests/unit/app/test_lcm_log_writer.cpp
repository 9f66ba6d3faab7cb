// Our LCM log writer against liblcm's own reader (lcm::LogFile): every event
// comes back with its channel, bytes, event number and its message's utime as
// the event time (bench time, never going back), so lcm-logplayer plays a
// --fast replay's log at the bench's speed.
#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>

#include <algorithm>
#include <cstdio>
#include <string>

#include "daemon/app/lcm_log_writer.h"
#include "daemon/app/lcm_output.h"

namespace resolver {
namespace {

TEST(LcmLogWriter, ParsesOnlyWriteAndAppendFileUrls) {
  const auto w = LcmLogWriter::parse_url("file:///tmp/x.lcmlog?mode=w");
  ASSERT_TRUE(w.has_value());
  EXPECT_EQ(w->path, "/tmp/x.lcmlog");
  EXPECT_FALSE(w->append);
  const auto a = LcmLogWriter::parse_url("file://rel.lcmlog?mode=a");
  ASSERT_TRUE(a.has_value());
  EXPECT_EQ(a->path, "rel.lcmlog");
  EXPECT_TRUE(a->append);
  // Everything else stays with liblcm.
  EXPECT_FALSE(LcmLogWriter::parse_url("file:///tmp/x.lcmlog").has_value());           // liblcm default: read
  EXPECT_FALSE(LcmLogWriter::parse_url("file:///tmp/x.lcmlog?mode=r").has_value());
  EXPECT_FALSE(LcmLogWriter::parse_url("file:///tmp/x.lcmlog?mode=w&speed=2").has_value());
  EXPECT_FALSE(LcmLogWriter::parse_url("udpm://239.255.76.67:7667?ttl=0").has_value());
  EXPECT_FALSE(LcmLogWriter::parse_url("memq://").has_value());
  EXPECT_FALSE(LcmLogWriter::parse_url("file://?mode=w").has_value());
}

TEST(LcmLogWriter, LiblcmReadsBackEveryEvent) {
  const std::string path = std::string(RESOLVER_BINARY_DIR) + "/writer_test.lcmlog";
  constexpr int kEvents = 20000;  // > one 256 KiB buffer: the flush path runs
  constexpr std::int64_t kT0 = 1'700'000'000'000'000;  // [us] bench time of the first sample
  constexpr std::int64_t kPeriod = 500;                // [us] 2 kHz
  {
    LcmOutput out("file://" + path + "?mode=w", LcmChannels{});
    for (int i = 0; i < kEvents; ++i) {
      angle_t a{};
      a.utime = kT0 + kPeriod * i;
      a.sample_index = 3 * static_cast<std::int64_t>(i);
      a.theta_rd = 0.001 * i;
      out.publish(a);
    }
    estimate_t e{};
    e.utime = kT0;  // older than the last angle_t (a result published late): the event time must not go back
    e.method = "hwang_integral";
    e.num_params = 1;
    e.param_name = {"amplitude_imbalance.alpha"};
    e.value = {0.003};
    e.std_error = {1e-6};
    out.publish(e);
    EXPECT_EQ(out.published(), static_cast<std::uint64_t>(kEvents + 1));
    EXPECT_EQ(out.publish_failures(), 0U);
  }
  lcm::LogFile log(path, "r");
  ASSERT_TRUE(log.good());
  int n = 0;
  while (const lcm::LogEvent* ev = log.readNextEvent()) {
    EXPECT_EQ(ev->eventnum, n);
    EXPECT_EQ(ev->timestamp, kT0 + kPeriod * std::min(n, kEvents - 1)) << "event " << n;
    if (n < kEvents) {
      ASSERT_EQ(ev->channel, "RESOLVER_ANGLE");
      angle_t a{};
      ASSERT_EQ(a.decode(ev->data, 0, ev->datalen), ev->datalen);
      EXPECT_EQ(a.utime, kT0 + kPeriod * n);
      EXPECT_EQ(a.sample_index, 3 * n);
      EXPECT_DOUBLE_EQ(a.theta_rd, 0.001 * n);
    } else {
      ASSERT_EQ(ev->channel, "RESOLVER_ESTIMATE");
      estimate_t e{};
      ASSERT_EQ(e.decode(ev->data, 0, ev->datalen), ev->datalen);
      EXPECT_EQ(e.param_name.at(0), "amplitude_imbalance.alpha");
      EXPECT_DOUBLE_EQ(e.value.at(0), 0.003);
    }
    ++n;
  }
  EXPECT_EQ(n, kEvents + 1);
  if (!::testing::Test::HasFailure()) std::remove(path.c_str());
}

TEST(LcmLogWriter, UnwritablePathNamesTheFile) {
  try {
    LcmOutput out("file:///nonexistent-dir/x.lcmlog?mode=w", LcmChannels{});
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent-dir/x.lcmlog"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace resolver
