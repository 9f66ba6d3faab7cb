// The report's SVG helper: text is escaped, odd data (NaN, <= 0 on a log axis, no
// points at all) never reaches the markup, lines break where asked, ticks are where
// a reader expects them.
#include "tools/model/svg_plot.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

namespace resolver::svg {
namespace {

int count(const std::string& s, const std::string& what) {
  int n = 0;
  for (auto p = s.find(what); p != std::string::npos; p = s.find(what, p + 1)) ++n;
  return n;
}

Plot line_plot(std::vector<double> x, std::vector<double> y) {
  Plot p;
  p.id = "t";
  p.title = "t";
  p.x.label = "x [s]";
  p.y.label = "y [A]";
  Series s;
  s.label = "s";
  s.color = "red";
  s.x = std::move(x);
  s.y = std::move(y);
  p.series.push_back(s);
  return p;
}

TEST(SvgPlot, EscapesTextAndAttributes) {
  EXPECT_EQ(escape(R"(<a href="x">'&'</a>)"), "&lt;a href=&quot;x&quot;&gt;&#39;&amp;&#39;&lt;/a&gt;");
  Plot p = line_plot({0, 1}, {0, 1});
  p.title = "<script>";
  p.series[0].label = "a & b";
  const std::string svg = render(p);
  EXPECT_EQ(svg.find("<script>"), std::string::npos);
  EXPECT_NE(svg.find("&lt;script&gt;"), std::string::npos);
  EXPECT_NE(svg.find("a &amp; b"), std::string::npos);
}

TEST(SvgPlot, NonFinitePointsBreakTheLineAndNeverReachTheMarkup) {
  const std::string svg = render(line_plot({0, 1, 2, 3, 4}, {0, 1, NAN, 3, INFINITY}));
  EXPECT_EQ(count(svg, "<polyline"), 1);  // 0-1, then 3 alone (no line of one point)
  EXPECT_EQ(svg.find("nan"), std::string::npos);
  EXPECT_EQ(svg.find("inf"), std::string::npos);
}

TEST(SvgPlot, MaxXStepBreaksAWrappedAngle) {
  Plot p = line_plot({0, 100, 200, 300, 10, 110}, {0, 1, 0, 1, 0, 1});
  EXPECT_EQ(count(render(p), "<polyline"), 1);  // without max_x_step: one line through all
  p.series[0].max_x_step = 150;
  EXPECT_EQ(count(render(p), "<polyline"), 2);  // 0..300, then 10..110
}

TEST(SvgPlot, EmptyPlotSaysNoData) {
  Plot p = line_plot({}, {});
  p.y.log = true;
  const std::string svg = render(p);
  EXPECT_NE(svg.find(">no data<"), std::string::npos);
  EXPECT_EQ(svg.rfind("</svg>"), svg.size() - 6);
}

TEST(SvgPlot, TicksOnAFixedAngleAxisAndDecadesOnALogAxis) {
  Plot p = line_plot({10, 350}, {0.002, 3.0});
  p.x.lo = 0;
  p.x.hi = 360;
  p.x.tick_step = 45;
  p.y.log = true;
  const std::string svg = render(p);
  for (const char* t : {">0<", ">45<", ">180<", ">360<", ">1e-3<", ">0.01<", ">1<", ">10<"}) {
    EXPECT_NE(svg.find(t), std::string::npos) << t;
  }
  EXPECT_EQ(svg.find(">405<"), std::string::npos);
}

TEST(SvgPlot, BarsSkipValuesALogAxisCannotShow) {
  Plot p;
  p.id = "b";
  p.x.categories = {"0", "1", "2"};
  p.y.log = true;
  p.bars.push_back({"step 1", "blue", {1e-3, 0.0, NAN}});
  EXPECT_EQ(count(render(p), "</rect>"), 1);  // one bar (frame and clip rects are self-closing)
}

}  // namespace
}  // namespace resolver::svg
