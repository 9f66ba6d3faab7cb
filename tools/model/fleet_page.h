// resolver-model fleet's page (issue 24 item 3): DIR/fleet.html, the fleet on one
// self-contained page in the single-log report's style and skeleton (html_page.h:
// embedded uPlot, report_page.js and the styles; web/fleet_page.{js,css} add error
// bars, outlier labels and the unit under the pointer). It shows
//
//   - the units: how many explained / missing_effect / unexplained / failed (the failed
//     ones named with their reason), the bench's p_r and p, the program's version;
//   - per fitted parameter: the summary statistics and a strip plot of its value over
//     the units (standard errors as error bars) with the median, the robust spread
//     band and the outlier threshold, the outlier units marked and labelled;
//   - the effects the units' discovery proposed (and needed), most units first;
//   - the outlier units (parameter, value, robust z) and every unit (verdict,
//     residual / floor, links to its unit.json and calibration files).
//
// Like fleet.json it is made from files only (DIR/fleet.json and DIR/UNIT/unit.json),
// so `fleet --summarize DIR` (and the Dask client, which calls it) writes the same page.
#pragma once

#include <map>
#include <string>

#include "tools/model/json_value.h"

namespace resolver {

/// What the page is made of.
struct FleetPageInput {
  std::string title;                        ///< the fleet's folder, as shown
  json::Json fleet;                         ///< DIR/fleet.json (summarize_fleet's)
  std::map<std::string, json::Json> units;  ///< unit id -> its DIR/UNIT/unit.json; absent: none or unreadable
  std::string version;                      ///< the --version line of the program writing the page
};

/// The page. Pure. Throws std::out_of_range or std::runtime_error when `fleet` lacks a
/// member summarize_fleet writes.
[[nodiscard]] std::string format_fleet_html(const FleetPageInput& in);

/// Reads DIR/fleet.json and the unit.json of every unit it names, writes DIR/fleet.html.
/// Throws std::system_error when fleet.json cannot be read or the page cannot be written,
/// std::runtime_error when fleet.json is not JSON; an unreadable unit.json only loses
/// that unit's details on the page.
void write_fleet_page(const std::string& out_dir);

}  // namespace resolver
