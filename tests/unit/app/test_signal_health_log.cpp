// resolverd's side of signal health: the ADC full scale comes from the DBC's
// sin/cos signals (their range, else their raw bits), a fault is printed once
// when it starts and once when it ends, a flapping one stops being printed but
// keeps being counted, and health_t carries every fault by its stable name.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <sstream>
#include <string>

#include "daemon/app/signal_health_log.h"
#include "daemon/dbc/dbc_parser.h"

namespace resolver {
namespace {

std::shared_ptr<const FrameDecoder> decoder_for(const std::string& sin_cos_signals) {
  const std::string text = "VERSION \"\"\nBU_: INV RD\nBO_ 256 FB: 8 INV\n SG_ counter : 0|8@1+ (1,0) [0|255] \"\" RD\n" +
                           sin_cos_signals + "\n";
  auto db = std::make_shared<const dbc::Database>(dbc::parse_dbc(text, "test.dbc"));
  SignalMap m;
  m.roles[static_cast<std::size_t>(Role::kSin)] = SignalRef{"FB", "s"};
  m.roles[static_cast<std::size_t>(Role::kCos)] = SignalRef{"FB", "c"};
  m.crc = CrcAlgorithm::kNone;
  m.crc_signal = "";
  m.bench_info_message = "";
  return std::make_shared<const FrameDecoder>(db, m);
}

TEST(SignalHealthLog, FullScaleFromTheDbcRangeOrRawBits) {
  const DaemonConfig config;
  // The bench layout: [-32768|32767] counts: clips at 32767, half a count of margin.
  const auto bench = health_config_for(config, *decoder_for(" SG_ s : 8|16@1- (1,0) [-32768|32767] \"\" RD\n"
                                                            " SG_ c : 24|16@1- (1,0) [-32768|32767] \"\" RD"));
  EXPECT_DOUBLE_EQ(bench.full_scale, 32767.0);
  EXPECT_DOUBLE_EQ(bench.clip_margin, 0.5);
  // No declared range ([0|0]): a 12-bit signed raw field in volts (1 mV/bit) clips at 2.047 V;
  // the smaller of the two channels counts.
  const auto raw = health_config_for(config, *decoder_for(" SG_ s : 8|12@1- (0.001,0) [0|0] \"V\" RD\n"
                                                          " SG_ c : 24|16@1- (0.001,0) [0|0] \"V\" RD"));
  EXPECT_NEAR(raw.full_scale, 2.047, 1e-12);
  EXPECT_NEAR(raw.clip_margin, 0.0005, 1e-12);
  // [health] full_scale wins over the DBC.
  DaemonConfig set;
  set.health.full_scale = 1000.0;
  set.health_full_scale_set = true;
  EXPECT_DOUBLE_EQ(health_config_for(set, *decoder_for(" SG_ s : 8|16@1- (1,0) [-32768|32767] \"\" RD\n"
                                                       " SG_ c : 24|16@1- (1,0) [-32768|32767] \"\" RD"))
                       .full_scale,
                   1000.0);
}

Sample sample_at(std::int64_t k, double amplitude) {
  Sample s;
  s.index = k;
  s.t = static_cast<double>(k) / 2000.0;
  const double theta = 0.05 * static_cast<double>(k);
  s.has_sincos = true;
  s.sin = std::round(amplitude * std::sin(theta));
  s.cos = std::round(amplitude * std::cos(theta));
  s.has_rd = true;
  s.theta_rd = wrap_2pi(theta);
  return s;
}

TEST(SignalHealthLog, PrintsStartAndEndOnceAndFillsHealthT) {
  std::ostringstream out;
  SignalHealthLog log(SignalHealthConfig{}, 3, 2000.0, out);
  for (std::int64_t k = 0; k < 6000; ++k) log.add(sample_at(k, k >= 2000 && k < 4000 ? 0.0 : 26000.0));
  log.finish();
  const std::string text = out.str();
  EXPECT_NE(text.find("resolverd: signal fault loss_of_signal started 1.000 s into the input (sample 2000)"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("resolverd: signal fault loss_of_signal ended 2.000 s into the input (sample 4000); 2000 sample(s)"),
            std::string::npos)
      << text;
  EXPECT_EQ(text.find("started", text.find("started") + 1), std::string::npos) << "one start only:\n" << text;
  health_t h{};
  log.fill(h);
  ASSERT_EQ(h.num_faults, 7);
  EXPECT_EQ(h.fault_name.front(), "loss_of_signal");
  EXPECT_EQ(h.fault_count.front(), 2000);
  EXPECT_EQ(h.fault_active.front(), 0);
  EXPECT_EQ(h.fault_name.back(), "outliers");
  EXPECT_TRUE(std::isfinite(h.sincos_amplitude));
  health_t empty{};
  log.fill(empty);
  EXPECT_TRUE(std::isnan(empty.sincos_amplitude)) << "no sample since the last health_t";
  const SignalHealthSummary s = log.summary();
  EXPECT_NEAR(s.fault(SignalFault::kLossOfSignal).share, 1.0 / 3.0, 1e-12);
}

TEST(SignalHealthLog, AFlappingFaultIsCountedNotPrintedForever) {
  std::ostringstream out;
  SignalHealthLog log(SignalHealthConfig{}, 3, 2000.0, out);
  // 30 episodes of loss of signal, 0.1 s each, 0.1 s apart.
  for (std::int64_t k = 0; k < 12000; ++k) log.add(sample_at(k, (k / 200) % 2 == 1 ? 0.0 : 26000.0));
  log.finish();
  const std::string text = out.str();
  std::size_t starts = 0;
  for (std::size_t at = 0; (at = text.find("loss_of_signal started", at)) != std::string::npos; ++at) ++starts;
  EXPECT_EQ(starts, 10U) << text;
  EXPECT_NE(text.find("loss_of_signal keeps coming back"), std::string::npos) << text;
  EXPECT_EQ(log.monitor().fault(SignalFault::kLossOfSignal).episodes, 30);
}

}  // namespace
}  // namespace resolver
