// The report's pieces without a log: angle bins (means, spreads, the samples' mean
// angle, empty bins), the JSON text the page embeds (nothing can close its <script>),
// the export's file names and units, and a page made from a hand-built run (the
// suggested custom block, units in the parameter table, no plot without data).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "tools/model/export_data.h"
#include "tools/model/html_report.h"
#include "tools/model/json_text.h"
#include "tools/model/report_data.h"

namespace resolver {
namespace {

constexpr double kPi = std::numbers::pi;

double deg(double d) { return d * kPi / 180.0; }

TEST(AngleBinner, MeansSpreadsAndTheSamplesMeanAngle) {
  report::AngleBinner b(4, 2.0);  // 90 deg bins, y doubled
  b.add(deg(10), 1.0);
  b.add(deg(30), 3.0);
  b.add(deg(100), -1.0);
  b.add(deg(-10), 5.0);                                   // wraps to 350 deg: the last bin
  b.add(deg(200), std::numeric_limits<double>::quiet_NaN());  // skipped
  const report::AngleBins r = b.result();
  ASSERT_EQ(r.mean.size(), 4U);
  EXPECT_EQ(r.filled, 3);
  EXPECT_DOUBLE_EQ(r.mean[0], 4.0);  // (2 + 6) / 2
  EXPECT_DOUBLE_EQ(r.sd[0], 2.0);    // population spread of {2, 6}
  EXPECT_NEAR(r.centre[0], 20.0, 1e-12);  // where the samples are, not the bin's centre (45)
  EXPECT_DOUBLE_EQ(r.mean[1], -2.0);
  EXPECT_DOUBLE_EQ(r.sd[1], 0.0);
  EXPECT_TRUE(std::isnan(r.mean[2]));     // no sample between 180 and 270 deg
  EXPECT_DOUBLE_EQ(r.centre[2], 225.0);   // an empty bin sits at its centre
  EXPECT_DOUBLE_EQ(r.count[2], 0.0);
  EXPECT_NEAR(r.centre[3], 350.0, 1e-9);
  EXPECT_DOUBLE_EQ(r.mean[3], 10.0);
}

TEST(AngleBinner, EvenlySpreadSamplesFillEveryBin) {
  // An incommensurate stride (golden ratio of a turn) fills all 180 bins with 4000 samples.
  std::vector<double> angle, y;
  for (int i = 0; i < 4000; ++i) {
    angle.push_back(2.0 * kPi * std::fmod(i * 0.6180339887498949, 1.0));
    y.push_back(std::sin(2.0 * angle.back()));
  }
  const report::AngleBins r = report::bin_by_angle(angle, y, report::kAngleBins);
  EXPECT_EQ(r.filled, report::kAngleBins);
  // The mean of sin 2theta over a 2 deg bin is within the bin's slope of the curve at its samples' mean angle.
  for (std::size_t k = 0; k < r.mean.size(); ++k) {
    EXPECT_NEAR(r.mean[k], std::sin(2.0 * deg(r.centre[k])), 2.0 * deg(2.0) * deg(2.0)) << k;
  }
}

TEST(JsonText, NothingClosesTheScriptElement) {
  const std::string s = json::str("a</script><!--\"\\\n\x01&");
  EXPECT_EQ(s, "\"a\\u003c/script\\u003e\\u003c!--\\\"\\\\\\n\\u0001\\u0026\"");
  EXPECT_EQ(json::num(std::numeric_limits<double>::quiet_NaN()), "null");
  EXPECT_EQ(json::num(-std::numeric_limits<double>::infinity()), "null");
  EXPECT_EQ(json::array({1.5, std::numeric_limits<double>::quiet_NaN(), 1e-7}, 3), "[1.5,null,1e-07]");
}

TEST(ExportNames, ParamsFileAndUnits) {
  EXPECT_EQ(params_csv_path("out.csv"), "out.params.csv");
  EXPECT_EQ(params_csv_path("dir.v2/out"), "dir.v2/out.params.csv");
  EXPECT_EQ(params_csv_path("./.hidden"), "./.hidden.params.csv");
  EXPECT_EQ(report::bare_unit("[rad]"), "rad");
  EXPECT_EQ(report::bare_unit("A"), "A");
  EXPECT_EQ(report::bare_unit("[fraction of fundamental]"), "fraction of fundamental");
}

TEST(PlotsJson, NanIsNullAndLabelsAreEscaped) {
  report::Plot p;
  p.id = "t";
  p.x.unit = "deg";
  p.x.column = "theta_deg";
  p.y.unit = "arcmin";
  p.y.column = "eps_arcmin";
  report::Series s;
  s.label = "a <b>";
  s.x = {1.0, 2.0};
  s.y = {std::numeric_limits<double>::quiet_NaN(), 3.0};
  p.series.push_back(s);
  const std::string j = report::plots_json({p});
  EXPECT_NE(j.find("\"y\":[null,3]"), std::string::npos) << j;
  EXPECT_NE(j.find("\"label\":\"a \\u003cb\\u003e\""), std::string::npos) << j;
  EXPECT_NE(j.find("\"lo\":null"), std::string::npos) << j;
}

DiscoveryRun hand_made_run() {
  Explanation ex;
  ex.fit.effects = {"amplitude_imbalance"};
  ex.fit.params = {{"amplitude_imbalance.alpha", 0.003, 1e-6, "[1]"}};
  SignalResidual pos;
  pos.signal = "position_error";
  pos.rms = 3e-4;
  pos.floor = 3e-5;
  pos.raw_rms = 1e-3;
  pos.held_back_rms = 3.1e-4;
  pos.rows = 1000;
  ex.fit.signals = {pos};
  ex.fit.residual_rms_rad = pos.rms;
  ex.fit.noise_floor_rad = pos.floor;
  ex.fit.floors.rd.chosen = 3e-5;
  ex.fit.floors.rd.source = "standstill";
  ex.fit.floors.rd.standstill = 3e-5;
  ex.fit.floors.rd.standstill_samples = 400;
  ex.verdict = Verdict::kUnexplained;
  ex.summary = "unexplained: no catalog effect";
  ex.suggested_custom = "[[model.custom]]\nname = \"drift\"\nterms = [\"t*sin(2*theta)\"]  # a < b\n";
  DiscoveryRun run;
  run.steps.push_back(ex);
  run.stopped = "done: no catalog effect explains the rest of the residual";
  return run;
}

TEST(HtmlReport, SuggestedCustomBlockUnitsAndNoPlotWithoutRows) {
  LogSamples log;
  const std::string page = format_model_html(hand_made_run(), log, "dir/bench.log", 1.5);
  EXPECT_NE(page.find("<h2 id=\"custom\">Suggested custom effect</h2>"), std::string::npos);
  EXPECT_NE(page.find("<pre class=\"custom\">[[model.custom]]\nname = &quot;drift&quot;"), std::string::npos);
  EXPECT_NE(page.find("# a &lt; b"), std::string::npos);
  // The parameter's unit, without the catalog's brackets.
  EXPECT_NE(page.find("<code>amplitude_imbalance.alpha</code></td><td class=\"num\">0.003</td><td "
                      "class=\"num\">1e-06</td><td>1</td>"),
            std::string::npos);
  EXPECT_NE(page.find("<b>standstill</b>"), std::string::npos);
  EXPECT_NE(page.find("Unexplained: no effect in the catalog"), std::string::npos);
  // No rows (run.log unset): no angle plot, and the page says why there are no dq plots.
  EXPECT_EQ(page.find("data-plot=\"pe\""), std::string::npos);
  EXPECT_NE(page.find("data-plot=\"spec\""), std::string::npos);
  EXPECT_NE(page.find("no dq-current plots"), std::string::npos);
  // Inline scripts only; the data element cannot be closed early by a label.
  EXPECT_EQ(page.find("<script src"), std::string::npos);
  const auto data = page.find("<script type=\"application/json\" id=\"report-data\">");
  ASSERT_NE(data, std::string::npos);
  const auto end = page.find("</script>", data);
  EXPECT_EQ(page.substr(data, end - data).find('<', 1), std::string::npos);
}

}  // namespace
}  // namespace resolver
