// Small SVG plots for the resolver-model HTML report: axes with ticks and units,
// lines, dots, grouped bars, horizontal reference lines (noise floors), a legend.
// The result is one <svg> element to inline in a page: no JavaScript, no fonts,
// no external files. Hovering a bar shows its value (an SVG <title>, no script).
//
// Pure string building; nothing here throws on odd data: non-finite points are
// skipped (and break a line), an empty plot says "no data".
#pragma once

#include <limits>
#include <string>
#include <string_view>
#include <vector>

namespace resolver::svg {

/// Escapes & < > " ' so any text is safe in XML/HTML text and attribute values.
[[nodiscard]] std::string escape(std::string_view text);

enum class Mark { kLine, kDots, kLineDots };

/// A set of (x, y) points drawn as a line, dots or both.
struct Series {
  std::string label;         ///< legend text (empty: not in the legend)
  std::string color;         ///< any CSS colour
  std::vector<double> x, y;  ///< same length
  Mark mark = Mark::kLine;
  double size = 1.5;  ///< [px] line width, or dot diameter
  double opacity = 1.0;
  bool dashed = false;
  /// > 0: a new line starts where x moves back or jumps forward by more than this, so a
  /// wrapped angle, or decimated samples that skip round the revolution, do not draw
  /// lines across the plot (0: one line through all points).
  double max_x_step = 0.0;
};

/// One bar per category of a categorical x axis; several Bars of a plot stand side by side.
struct Bars {
  std::string label;
  std::string color;
  std::vector<double> values;  ///< per category; NaN (or <= 0 on a log axis): no bar
};

/// A horizontal reference line across the plot, e.g. a noise floor.
struct HLine {
  double y = 0.0;
  std::string label;  ///< legend text
  std::string color = "#555";
  bool dashed = true;
};

struct Axis {
  std::string label;                                     ///< with its unit, e.g. "θ [deg]"
  bool log = false;                                      ///< decades; values <= 0 are not drawn
  double lo = std::numeric_limits<double>::quiet_NaN();  ///< fixed range; NaN: from the data
  double hi = std::numeric_limits<double>::quiet_NaN();
  double tick_step = 0.0;               ///< linear axes: fixed tick spacing; 0: automatic
  std::vector<std::string> categories;  ///< x only: a categorical axis (bar charts), positions 0..n-1
};

struct Plot {
  std::string id;  ///< unique within the page (clip path id)
  std::string title;
  Axis x, y;
  std::vector<Series> series;
  std::vector<Bars> bars;
  std::vector<HLine> hlines;
  int width = 1100;  ///< [px]
  int height = 320;  ///< [px]
};

/// The plot as one <svg> element.
[[nodiscard]] std::string render(const Plot& plot);

}  // namespace resolver::svg
