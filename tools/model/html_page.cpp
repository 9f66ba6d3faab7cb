#include "tools/model/html_page.h"

#include <fmt/format.h>

#include <stdexcept>

#include "tools/model/report_assets.h"

namespace resolver::html {

namespace {

std::string figure(const report::Plot& p) {
  return fmt::format(
      "<figure class=\"plot{}\" id=\"fig-{}\"><div class=\"plot-title\">{}</div>"
      "<div class=\"chart\" data-plot=\"{}\"></div><div class=\"legend\" data-legend=\"{}\"></div>"
      "<div class=\"tools\"><button type=\"button\" data-csv=\"{}\">download CSV</button> "
      "<button type=\"button\" data-reset=\"{}\">reset zoom</button> <span class=\"readout\" data-readout=\"{}\"></span>"
      "</div><figcaption>{}</figcaption></figure>\n",
      p.half ? " half" : "", p.id, escape(p.title), p.id, p.id, p.id, p.id, p.id, escape(p.caption));
}

/// Text for an inline <script>: nothing in it may close the element early.
std::string_view script_safe(std::string_view js, std::string_view what) {
  if (js.find("</script") != std::string_view::npos || js.find("<!--") != std::string_view::npos) {
    throw std::runtime_error(fmt::format("{} contains </script or <!--: it cannot be inlined", what));
  }
  return js;
}

}  // namespace

std::string escape(std::string_view text) {
  std::string o;
  o.reserve(text.size());
  for (const char c : text) {
    switch (c) {
      case '&': o += "&amp;"; break;
      case '<': o += "&lt;"; break;
      case '>': o += "&gt;"; break;
      case '"': o += "&quot;"; break;
      case '\'': o += "&#39;"; break;
      default: o += c;
    }
  }
  return o;
}

std::string table(std::string_view cls, const std::vector<std::string>& header,
                  const std::vector<std::vector<std::string>>& rows) {
  std::string o = fmt::format("<table class=\"{}\"><tr>", cls);
  for (const auto& h : header) o += "<th>" + h + "</th>";
  o += "</tr>\n";
  for (const auto& r : rows) {
    o += "<tr>";
    for (const auto& c : r) o += c.starts_with("<td") ? c : "<td>" + c + "</td>";
    o += "</tr>\n";
  }
  return o + "</table>\n";
}

std::string num_cell(const std::string& text) { return "<td class=\"num\">" + text + "</td>"; }

std::string page_head(std::string_view title, std::string_view extra_css) {
  std::string o =
      "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n<meta name=\"viewport\" "
      "content=\"width=device-width\">\n";
  o += fmt::format("<title>{}</title>\n<style>{}</style>\n<style>{}</style>", escape(title), report_assets::uplot_css(),
                   report_assets::page_css());
  if (!extra_css.empty()) o += fmt::format("\n<style>{}</style>", extra_css);
  return o + "</head><body>\n";
}

std::string figures(const std::vector<report::Plot>& plots) {
  std::string o;
  for (std::size_t i = 0; i < plots.size(); ++i) {
    if (plots[i].half && i + 1 < plots.size() && plots[i + 1].half) {
      o += "<div class=\"row\">" + figure(plots[i]) + figure(plots[i + 1]) + "</div>\n";
      ++i;
    } else {
      o += figure(plots[i]);
    }
  }
  return o;
}

std::string page_tail(const std::vector<report::Plot>& plots, std::string_view extra_js, std::string_view extra_js_name) {
  std::string o = "<script type=\"application/json\" id=\"report-data\">{\"plots\":" + report::plots_json(plots) +
                  "}</script>\n";
  o += fmt::format("<script>/*! uPlot {}\n{}\n*/\n{}</script>\n", report_assets::uplot_version(),
                   script_safe(report_assets::uplot_license(), "uPlot's LICENSE"),
                   script_safe(report_assets::uplot_js(), "uPlot.iife.min.js"));
  o += fmt::format("<script>{}</script>\n", script_safe(report_assets::page_js(), "report_page.js"));
  if (!extra_js.empty()) o += fmt::format("<script>{}</script>\n", script_safe(extra_js, extra_js_name));
  return o + "</body></html>\n";
}

}  // namespace resolver::html
