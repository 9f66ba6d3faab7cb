#include "tools/model/svg_plot.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

namespace resolver::svg {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
// Layout [px]. The left margin holds tick labels like "-0.0125" and the rotated axis label.
constexpr double kLeft = 84.0, kRight = 16.0, kTitleH = 22.0, kLegendRowH = 18.0, kBottom = 46.0;
// Average glyph width of 12 px sans-serif, for laying out the legend without font metrics.
constexpr double kCharW = 6.6;

struct Range {
  double lo = kNaN, hi = kNaN;
  void add(double v, bool log) {
    if (!std::isfinite(v) || (log && v <= 0.0)) return;
    lo = std::isnan(lo) ? v : std::min(lo, v);
    hi = std::isnan(hi) ? v : std::max(hi, v);
  }
  [[nodiscard]] bool empty() const { return std::isnan(lo); }
};

struct Tick {
  double v;
  std::string label;
  bool labelled;
};

/// 1, 2 or 5 times a power of ten, about range / target.
double nice_step(double range, int target) {
  const double raw = range / target;
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  const double f = raw / mag;
  return (f < 1.5 ? 1.0 : f < 3.0 ? 2.0 : f < 7.0 ? 5.0 : 10.0) * mag;
}

std::string linear_label(double v, double step) {
  if (std::abs(v) < step * 1e-6) v = 0.0;  // no "-0" or "1e-17" at zero
  const double a = std::abs(step);
  if (a >= 1e-4 && a < 1e6) {
    const int decimals = std::max(0, static_cast<int>(-std::floor(std::log10(a) + 1e-9)));
    return fmt::format("{:.{}f}", v, decimals);
  }
  return fmt::format("{:.3g}", v);
}

/// Resolves an axis's range from the data and makes its ticks.
struct Scale {
  double lo = 0.0, hi = 1.0;
  bool log = false;
  double px0 = 0.0, px1 = 1.0;  ///< pixel positions of lo and hi
  std::vector<Tick> ticks;

  [[nodiscard]] double map(double v) const {
    const double a = log ? std::log10(lo) : lo, b = log ? std::log10(hi) : hi;
    const double u = log ? std::log10(v) : v;
    return px0 + (u - a) / (b - a) * (px1 - px0);
  }
  [[nodiscard]] bool inside(double v) const {
    return std::isfinite(v) && (!log || v > 0.0) && v >= lo - 1e-12 * std::abs(lo) && v <= hi + 1e-12 * std::abs(hi);
  }
};

Scale make_log_scale(const Axis& axis, Range r) {
  Scale s;
  s.log = true;
  if (r.empty()) r = {1e-3, 1.0};
  const int d0 = static_cast<int>(std::floor(std::log10(std::isnan(axis.lo) ? r.lo : axis.lo)));
  int d1 = static_cast<int>(std::ceil(std::log10(std::isnan(axis.hi) ? r.hi : axis.hi)));
  if (d1 <= d0) d1 = d0 + 1;
  s.lo = std::pow(10.0, d0);
  s.hi = std::pow(10.0, d1);
  const int every = (d1 - d0) > 8 ? 2 : 1;  // keep decade labels apart on tall ranges
  for (int d = d0; d <= d1; ++d) {
    const double v = std::pow(10.0, d);
    s.ticks.push_back({v, d >= -2 && d <= 3 ? fmt::format("{:g}", v) : fmt::format("1e{}", d), (d - d0) % every == 0});
    if (d < d1 && d1 - d0 <= 4) {
      s.ticks.push_back({2.0 * v, "", false});
      s.ticks.push_back({5.0 * v, "", false});
    }
  }
  return s;
}

Scale make_linear_scale(const Axis& axis, Range r) {
  Scale s;
  if (!std::isnan(axis.lo)) r.lo = axis.lo;
  if (!std::isnan(axis.hi)) r.hi = axis.hi;
  if (r.empty()) r = {0.0, 1.0};
  if (!(r.hi > r.lo)) {  // one value: a range around it
    const double pad = r.lo != 0.0 ? 0.1 * std::abs(r.lo) : 1.0;
    r = {r.lo - pad, r.hi + pad};
  }
  const double step = axis.tick_step > 0.0 ? axis.tick_step : nice_step(r.hi - r.lo, 6);
  // A data range is widened to whole ticks; a fixed range is kept as given.
  s.lo = std::isnan(axis.lo) ? std::floor(r.lo / step + 1e-9) * step : r.lo;
  s.hi = std::isnan(axis.hi) ? std::ceil(r.hi / step - 1e-9) * step : r.hi;
  if (!(s.hi > s.lo)) s.hi = s.lo + step;
  // Integer tick indices: summing the step would drift and drop the last tick.
  const auto i0 = static_cast<long long>(std::ceil(s.lo / step - 1e-9));
  const auto i1 = static_cast<long long>(std::floor(s.hi / step + 1e-9));
  for (long long i = i0; i <= i1 && i - i0 < 100; ++i) {
    const double v = static_cast<double>(i) * step;
    s.ticks.push_back({v, linear_label(v, step), true});
  }
  return s;
}

Scale make_category_scale(const Axis& axis) {
  Scale s;
  const auto n = static_cast<double>(axis.categories.size());
  s.lo = -0.5;
  s.hi = std::max(0.5, n - 0.5);
  for (std::size_t i = 0; i < axis.categories.size(); ++i) {
    s.ticks.push_back({static_cast<double>(i), axis.categories[i], true});
  }
  return s;
}

struct LegendItem {
  std::string label, color;
  enum Kind { kLine, kDashed, kDot, kBox } kind;
};

std::vector<LegendItem> legend_items(const Plot& p) {
  std::vector<LegendItem> out;
  for (const auto& s : p.series) {
    if (s.label.empty()) continue;
    out.push_back({s.label, s.color,
                   s.mark == Mark::kDots ? LegendItem::kDot
                   : s.dashed            ? LegendItem::kDashed
                                         : LegendItem::kLine});
  }
  for (const auto& b : p.bars) {
    if (!b.label.empty()) out.push_back({b.label, b.color, LegendItem::kBox});
  }
  for (const auto& h : p.hlines) {
    if (!h.label.empty()) out.push_back({h.label, h.color, h.dashed ? LegendItem::kDashed : LegendItem::kLine});
  }
  return out;
}

/// Lays the legend out in rows under the title; returns the markup and the rows used.
std::pair<std::string, int> legend(const std::vector<LegendItem>& items, double width) {
  std::string o;
  double x = kLeft;
  int row = 0;
  for (const auto& it : items) {
    const double w = 30.0 + kCharW * static_cast<double>(it.label.size()) + 16.0;
    if (x + w > width - kRight && x > kLeft) {
      x = kLeft;
      ++row;
    }
    const double y = kTitleH + 12.0 + row * kLegendRowH;
    const std::string c = escape(it.color);
    switch (it.kind) {
      case LegendItem::kDot:
        o += fmt::format(R"(<circle cx="{:.1f}" cy="{:.1f}" r="3.5" fill="{}"/>)", x + 12, y - 4, c);
        break;
      case LegendItem::kBox:
        o += fmt::format(R"(<rect x="{:.1f}" y="{:.1f}" width="20" height="10" fill="{}"/>)", x + 2, y - 9, c);
        break;
      default:
        o +=
            fmt::format(R"(<line x1="{:.1f}" y1="{:.1f}" x2="{:.1f}" y2="{:.1f}" stroke="{}" stroke-width="2.5"{}/>)",
                        x, y - 4, x + 24, y - 4, c, it.kind == LegendItem::kDashed ? R"( stroke-dasharray="6 4")" : "");
    }
    o += fmt::format(R"(<text x="{:.1f}" y="{:.1f}">{}</text>)", x + 30, y, escape(it.label));
    x += w;
  }
  return {o, items.empty() ? 0 : row + 1};
}

std::string dash(bool dashed) { return dashed ? R"( stroke-dasharray="6 4")" : ""; }

/// Polyline runs of the series (split at non-finite points and, if asked, where x jumps), then its dots.
std::string series_markup(const Series& s, const Scale& xs, const Scale& ys) {
  std::string o;
  const std::size_t n = std::min(s.x.size(), s.y.size());
  const std::string c = escape(s.color);
  if (s.mark != Mark::kDots) {
    std::string pts;
    int count = 0;
    auto flush = [&] {
      if (count > 1) {
        o += fmt::format(
            R"(<polyline fill="none" stroke="{}" stroke-width="{:.1f}" stroke-opacity="{:.2f}"{} points="{}"/>)", c,
            s.size, s.opacity, dash(s.dashed), pts);
      }
      pts.clear();
      count = 0;
    };
    for (std::size_t i = 0; i < n; ++i) {
      const bool ok = std::isfinite(s.x[i]) && std::isfinite(s.y[i]) && (!ys.log || s.y[i] > 0.0);
      const bool jump = s.max_x_step > 0.0 && i > 0 && (s.x[i] < s.x[i - 1] || s.x[i] - s.x[i - 1] > s.max_x_step);
      if (!ok || jump) flush();
      if (!ok) continue;
      pts += fmt::format("{}{:.1f},{:.1f}", pts.empty() ? "" : " ", xs.map(s.x[i]), ys.map(s.y[i]));
      ++count;
    }
    flush();
  }
  if (s.mark != Mark::kLine) {
    // Dots as zero-length round-capped path segments: one element for thousands of points.
    const double d = s.mark == Mark::kLineDots ? std::max(5.0, 2.5 * s.size) : s.size;
    std::string path;
    for (std::size_t i = 0; i < n; ++i) {
      if (!xs.inside(s.x[i]) || !ys.inside(s.y[i])) continue;
      path += fmt::format("M{:.1f} {:.1f}h0", xs.map(s.x[i]), ys.map(s.y[i]));
    }
    if (!path.empty()) {
      o += fmt::format(
          R"(<path fill="none" stroke="{}" stroke-width="{:.1f}" stroke-opacity="{:.2f}" stroke-linecap="round" d="{}"/>)",
          c, d, s.opacity, path);
    }
  }
  return o;
}

std::string bars_markup(const Plot& p, const Scale& xs, const Scale& ys) {
  std::string o;
  const double k = static_cast<double>(p.bars.size());
  const double group = 0.8;  // of a category's width
  const double base = ys.log ? ys.px0 : ys.map(std::clamp(0.0, ys.lo, ys.hi));
  for (std::size_t j = 0; j < p.bars.size(); ++j) {
    const Bars& b = p.bars[j];
    for (std::size_t i = 0; i < b.values.size() && i < p.x.categories.size(); ++i) {
      const double v = b.values[i];
      if (!std::isfinite(v) || (ys.log && v <= 0.0)) continue;
      const double x0 = xs.map(static_cast<double>(i) - group / 2 + group * static_cast<double>(j) / k);
      const double x1 = xs.map(static_cast<double>(i) - group / 2 + group * static_cast<double>(j + 1) / k);
      const double y = ys.map(std::clamp(v, ys.lo, ys.hi));
      o += fmt::format(
          R"(<rect x="{:.1f}" y="{:.1f}" width="{:.1f}" height="{:.1f}" fill="{}"><title>{}, {}: {:.3g}</title></rect>)",
          x0 + 0.5, std::min(y, base), std::max(1.0, x1 - x0 - 1.0), std::abs(base - y), escape(b.color),
          escape(b.label), escape(p.x.categories[i]), v);
    }
  }
  return o;
}

}  // namespace

std::string escape(std::string_view text) {
  std::string o;
  o.reserve(text.size());
  for (char ch : text) {
    switch (ch) {
      case '&':
        o += "&amp;";
        break;
      case '<':
        o += "&lt;";
        break;
      case '>':
        o += "&gt;";
        break;
      case '"':
        o += "&quot;";
        break;
      case '\'':
        o += "&#39;";
        break;
      default:
        o += ch;
    }
  }
  return o;
}

std::string render(const Plot& p) {
  const auto W = static_cast<double>(p.width), H = static_cast<double>(p.height);
  const auto items = legend_items(p);
  auto [legend_markup, legend_rows] = legend(items, W);
  const double top = kTitleH + 8.0 + legend_rows * kLegendRowH;

  Range xr, yr;
  bool any = false;
  for (const auto& s : p.series) {
    for (std::size_t i = 0; i < s.x.size() && i < s.y.size(); ++i) {
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i]) || (p.y.log && s.y[i] <= 0.0)) continue;
      xr.add(s.x[i], p.x.log);
      yr.add(s.y[i], p.y.log);
      any = true;
    }
  }
  for (const auto& b : p.bars) {
    for (double v : b.values) {
      if (std::isfinite(v) && (!p.y.log || v > 0.0)) any = true;
      yr.add(v, p.y.log);
    }
  }
  if (!p.bars.empty() && !p.y.log) yr.add(0.0, false);  // linear bars stand on zero
  for (const auto& h : p.hlines) yr.add(h.y, p.y.log);

  Scale xs = !p.x.categories.empty() ? make_category_scale(p.x)
             : p.x.log               ? make_log_scale(p.x, xr)
                                     : make_linear_scale(p.x, xr);
  Scale ys = p.y.log ? make_log_scale(p.y, yr) : make_linear_scale(p.y, yr);
  xs.px0 = kLeft;
  xs.px1 = W - kRight;
  ys.px0 = H - kBottom;
  ys.px1 = top;

  std::string o =
      fmt::format(R"(<svg class="plot" width="{}" height="{}" viewBox="0 0 {} {}" role="img" aria-label="{}">)",
                  p.width, p.height, p.width, p.height, escape(p.title));
  o += fmt::format(
      R"(<defs><clipPath id="clip-{}"><rect x="{:.1f}" y="{:.1f}" width="{:.1f}" height="{:.1f}"/></clipPath></defs>)",
      escape(p.id), xs.px0, ys.px1, xs.px1 - xs.px0, ys.px0 - ys.px1);
  o += fmt::format(R"(<text class="title" x="{:.1f}" y="16">{}</text>)", kLeft, escape(p.title));
  o += legend_markup;
  // Grid and ticks.
  for (const auto& t : ys.ticks) {
    const double y = ys.map(t.v);
    o += fmt::format(R"(<line class="{}" x1="{:.1f}" y1="{:.1f}" x2="{:.1f}" y2="{:.1f}"/>)",
                     t.labelled ? "grid" : "grid minor", xs.px0, y, xs.px1, y);
    if (t.labelled)
      o += fmt::format(R"(<text class="tick" x="{:.1f}" y="{:.1f}" text-anchor="end">{}</text>)", xs.px0 - 6, y + 4,
                       escape(t.label));
  }
  for (const auto& t : xs.ticks) {
    const double x = xs.map(t.v);
    if (p.x.categories.empty()) {
      o += fmt::format(R"(<line class="{}" x1="{:.1f}" y1="{:.1f}" x2="{:.1f}" y2="{:.1f}"/>)",
                       t.labelled ? "grid" : "grid minor", x, ys.px1, x, ys.px0);
    }
    if (t.labelled)
      o += fmt::format(R"(<text class="tick" x="{:.1f}" y="{:.1f}" text-anchor="middle">{}</text>)", x, ys.px0 + 16,
                       escape(t.label));
  }
  o += fmt::format(R"(<rect class="frame" x="{:.1f}" y="{:.1f}" width="{:.1f}" height="{:.1f}"/>)", xs.px0, ys.px1,
                   xs.px1 - xs.px0, ys.px0 - ys.px1);
  o += fmt::format(R"(<text class="axis" x="{:.1f}" y="{:.1f}" text-anchor="middle">{}</text>)", (xs.px0 + xs.px1) / 2,
                   H - 8, escape(p.x.label));
  o +=
      fmt::format(R"~(<text class="axis" transform="translate(16 {:.1f}) rotate(-90)" text-anchor="middle">{}</text>)~",
                  (ys.px0 + ys.px1) / 2, escape(p.y.label));
  // Data, clipped to the plot area.
  o += fmt::format(R"~(<g clip-path="url(#clip-{})">)~", escape(p.id));
  o += bars_markup(p, xs, ys);
  for (const auto& s : p.series) o += series_markup(s, xs, ys);
  for (const auto& h : p.hlines) {
    if (!ys.inside(h.y)) continue;
    o += fmt::format(R"(<line x1="{:.1f}" y1="{:.1f}" x2="{:.1f}" y2="{:.1f}" stroke="{}" stroke-width="1.5"{}/>)",
                     xs.px0, ys.map(h.y), xs.px1, ys.map(h.y), escape(h.color), dash(h.dashed));
  }
  o += "</g>";
  if (!any) {
    o += fmt::format(R"(<text class="nodata" x="{:.1f}" y="{:.1f}" text-anchor="middle">no data</text>)",
                     (xs.px0 + xs.px1) / 2, (ys.px0 + ys.px1) / 2);
  }
  return o + "</svg>";
}

}  // namespace resolver::svg
