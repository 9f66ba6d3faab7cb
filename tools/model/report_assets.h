// The report page's scripts and styles, embedded into resolver-model at build time
// (tools/model/CMakeLists.txt, embed_assets.cmake): uPlot's dist files from the npm
// package pinned in web/package-lock.json (installed by `npm ci` into the build
// tree, never checked in) and the pages' own scripts and styles from web/.
// Embedded rather than read from an install directory so that the binary alone, from
// the build tree or a package, writes the one self-contained page.
#pragma once

#include <string_view>

namespace resolver::report_assets {

[[nodiscard]] std::string_view uplot_js();       ///< uPlot.iife.min.js
[[nodiscard]] std::string_view uplot_css();      ///< uPlot.min.css
[[nodiscard]] std::string_view uplot_license();  ///< its LICENSE (MIT: the notice travels with the copy)
[[nodiscard]] std::string_view uplot_version();  ///< e.g. "1.6.32", from the installed package.json
[[nodiscard]] std::string_view page_js();        ///< web/report_page.js
[[nodiscard]] std::string_view page_css();       ///< web/report_page.css
[[nodiscard]] std::string_view fleet_page_js();  ///< web/fleet_page.js (the fleet page only, after page_js)
[[nodiscard]] std::string_view fleet_page_css(); ///< web/fleet_page.css (the fleet page only, after page_css)

}  // namespace resolver::report_assets
