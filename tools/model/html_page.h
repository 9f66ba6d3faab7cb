// The skeleton every resolver-model HTML page shares (the single-log report,
// html_report.h, and the fleet page, fleet_page.h): the head with the embedded
// styles, escaping, tables, the plot figures, and the tail that inlines the plots'
// data, uPlot and the page's script (report_assets.h). A page is
//
//   page_head(title) + its own body (tables, figures(plots), ...) + page_tail(plots)
//
// and references nothing outside itself, so it works from file:// with no network.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "tools/model/report_data.h"

namespace resolver::html {

/// Escapes & < > " ' so any text is safe in HTML text and attribute values.
[[nodiscard]] std::string escape(std::string_view text);

/// A table: header cells (HTML allowed: units with <sub>) and rows of cells (already
/// HTML; a cell that starts with "<td" is taken as the whole cell).
[[nodiscard]] std::string table(std::string_view cls, const std::vector<std::string>& header,
                                const std::vector<std::vector<std::string>>& rows);

/// A right-aligned numeric cell around `text` (already HTML).
[[nodiscard]] std::string num_cell(const std::string& text);

/// "<!DOCTYPE html>" up to and including "<body>\n": the title (escaped here), uPlot's
/// and the page's styles, then `extra_css` in a style element of its own when not empty.
[[nodiscard]] std::string page_head(std::string_view title, std::string_view extra_css = {});

/// One <figure> per plot (the page's script draws into it), two half plots to a row.
[[nodiscard]] std::string figures(const std::vector<report::Plot>& plots);

/// The plots' data (#report-data), uPlot with its licence, the page's script, then
/// `extra_js` (named `extra_js_name` in errors) when not empty, and "</body></html>\n".
/// Throws std::runtime_error when a script contains "</script" or "<!--".
[[nodiscard]] std::string page_tail(const std::vector<report::Plot>& plots, std::string_view extra_js = {},
                                    std::string_view extra_js_name = {});

}  // namespace resolver::html
