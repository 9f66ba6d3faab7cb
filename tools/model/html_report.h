// resolver-model report: one self-contained HTML page of a discovery run
// (discovery_run.h): verdict, what the statistics cover, the steps, the final
// model's parameters with units, residuals against the noise floors and where the
// floors come from, held-back validation, outliers, whiteness, the candidates, the
// suggested custom effect, and interactive plots (report_data.h: binned means with a
// spread band over the model; one residual panel per step; spectra; i_d, i_q vs θ_e).
//
// One file, no external reference: uPlot (npm, pinned in web/package-lock.json) and
// the page's script and style are embedded at build time (report_assets.h); the
// plots' data is one inline JSON element. Zoom (drag, wheel), pan (shift-drag),
// reset (double-click) and a CSV download per plot are in web/report_page.js.
#pragma once

#include <string>
#include <string_view>

#include "tools/model/discovery_run.h"
#include "tools/model/log_samples.h"

namespace resolver {

/// The HTML page. `log_path` is shown as given; `explained_ratio` is the option the run used;
/// `pooled_section` (HTML, may be empty) goes before the notes: a pooled run's logs.
[[nodiscard]] std::string format_model_html(const DiscoveryRun& run, const LogSamples& log, std::string_view log_path,
                                            double explained_ratio, const std::string& pooled_section = "");

/// Writes `text` to `path` (replacing it). Throws std::system_error
/// "cannot write <path>: <reason>".
void write_text_file(const std::string& path, std::string_view text);

}  // namespace resolver
