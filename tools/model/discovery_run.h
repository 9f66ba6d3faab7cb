// The discovery loop of docs/ARCHITECTURE.md §8 run to its end on one log (what `resolver-model
// report` shows):
//
//   model ─► explain ─► verdict missing_effect? ─► add the best candidate ─► explain again ...
//
// at most max_steps passes over the same prepared rows. Plus the words every view of
// a run shares: a model's name, what a step added, the step's label and colour.
#pragma once

#include <cstddef>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "daemon/core/discovery/model_discovery.h"

namespace resolver {

struct DiscoveryRun {
  /// One explain pass per step: first the starting model, last the final one.
  /// While a step's verdict is missing_effect, its first candidate is what the next step adds.
  std::vector<Explanation> steps;
  std::string stopped;  ///< why the loop ended, in words
  /// The rows every step fitted (the page bins all of them, not only the plot series).
  std::shared_ptr<const PreparedLog> log;
};

/// Explains `effects`, then adds the best candidate and explains again while the
/// verdict is missing_effect, for at most max_steps passes. on_step(k) (may be empty)
/// is called before pass k = 1, 2, ...; options.progress sees the fraction of that
/// pass. Throws like explain_model when the starting model cannot be fitted; a later
/// step that cannot ends the run, and `stopped` says why.
[[nodiscard]] DiscoveryRun run_discovery(const DiscoveryInput& input, std::vector<std::string> effects,
                                         const DiscoveryOptions& options, int max_steps,
                                         const std::function<void(int)>& on_step = {});

/// The same on rows already prepared (a pooled log, pool.h).
[[nodiscard]] DiscoveryRun run_discovery(std::shared_ptr<const PreparedLog> log, std::vector<std::string> effects,
                                         const DiscoveryOptions& options, int max_steps,
                                         const std::function<void(int)>& on_step = {});

/// One line for the terminal: verdict, steps, final model and its residual.
[[nodiscard]] std::string summarize_discovery(const DiscoveryRun& run);

/// "a + b", or "(nuisance only)" for an empty model.
[[nodiscard]] std::string model_name(const ModelFit& fit);
/// Effects of `later` that `earlier` lacks, in order.
[[nodiscard]] std::vector<std::string> added_effects(const ModelFit& earlier, const ModelFit& later);
/// "step 1: a" for the first step, "step k: + b" for the later ones.
[[nodiscard]] std::string step_label(const DiscoveryRun& run, std::size_t step);
/// A CSS colour per step: the first red, the last blue, distinct hues in between,
/// so plots read as "before -> after".
[[nodiscard]] std::string step_color(std::size_t step, std::size_t steps);

}  // namespace resolver
