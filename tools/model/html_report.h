// resolver-model report: the discovery loop of DESIGN 7 run to its end on one log,
// and one self-contained HTML page of it (inline CSS and SVG; no JavaScript, no
// external files, so it can be mailed or archived with the log).
//
//   run_discovery:  model ─► explain_model ─► verdict missing_effect? ─► add the best
//                   candidate ─► explain again ... (at most max_steps passes)
//   format_model_html: the steps as a table, the final model's parameters, and plots:
//                   position error vs angle (measured, model, residual), residual
//                   spectrum by harmonic per step, residual vs speed per step, dq
//                   currents with the raw, compensated and reference angle; notes.
#pragma once

#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "daemon/core/discovery/model_discovery.h"
#include "tools/model/log_samples.h"

namespace resolver {

struct DiscoveryRun {
  /// One explain_model pass per step: first the starting model, last the final one.
  /// While a step's verdict is missing_effect, its first candidate is what the next step adds.
  std::vector<Explanation> steps;
  std::string stopped;  ///< why the loop ended, in words
};

/// Explains `effects`, then adds the best candidate and explains again while the
/// verdict is missing_effect, for at most max_steps passes. on_step(k) (may be empty)
/// is called before pass k = 1, 2, ...; options.progress sees the fraction of that
/// pass. Throws like explain_model when the starting model cannot be fitted; a later
/// step that cannot ends the run, and `stopped` says why.
[[nodiscard]] DiscoveryRun run_discovery(const DiscoveryInput& input, std::vector<std::string> effects,
                                         const DiscoveryOptions& options, int max_steps,
                                         const std::function<void(int)>& on_step = {});

/// One line for the terminal: verdict, steps, final model and its residual.
[[nodiscard]] std::string summarize_discovery(const DiscoveryRun& run);

/// The HTML page. `log_path` is shown as given; `explained_ratio` is the option the run used.
[[nodiscard]] std::string format_model_html(const DiscoveryRun& run, const LogSamples& log, std::string_view log_path,
                                            double explained_ratio);

/// Writes `text` to `path` (replacing it). Throws std::runtime_error
/// "cannot write <path>: <reason>".
void write_text_file(const std::string& path, std::string_view text);

}  // namespace resolver
