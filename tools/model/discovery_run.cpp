#include "tools/model/discovery_run.h"

#include <fmt/format.h>

#include <algorithm>
#include <exception>
#include <iterator>

#include "daemon/core/angles.h"

namespace resolver {

DiscoveryRun run_discovery(const DiscoveryInput& input, std::vector<std::string> effects,
                           const DiscoveryOptions& options, int max_steps, const std::function<void(int)>& on_step) {
  // Prepared once: every step fits the same rows.
  return run_discovery(std::make_shared<const PreparedLog>(prepare_log(input, options.prepare)), std::move(effects),
                       options, max_steps, on_step);
}

DiscoveryRun run_discovery(std::shared_ptr<const PreparedLog> prepared, std::vector<std::string> effects,
                           const DiscoveryOptions& options, int max_steps, const std::function<void(int)>& on_step) {
  DiscoveryRun run;
  max_steps = std::max(1, max_steps);
  run.log = std::move(prepared);
  const PreparedLog& log = *run.log;
  for (int step = 0; step < max_steps; ++step) {
    if (on_step) on_step(step + 1);
    try {
      run.steps.push_back(explain_prepared(log, effects, options));
    } catch (const std::exception& e) {
      if (run.steps.empty()) throw;
      run.stopped = fmt::format("adding {} failed: {}", effects.back(), e.what());
      return run;
    }
    const Explanation& ex = run.steps.back();
    if (ex.verdict != Verdict::kMissingEffect || ex.candidates.empty()) {
      run.stopped = ex.verdict == Verdict::kExplained ? "done: every signal is at the noise floor"
                                                      : "done: no catalog effect explains the rest of the residual";
      return run;
    }
    effects.push_back(ex.candidates.front().effect);
  }
  run.stopped = fmt::format("stopped at the limit of {} step{}; {} is proposed next", max_steps,
                            max_steps == 1 ? "" : "s", effects.back());
  return run;
}

std::string model_name(const ModelFit& fit) {
  return fit.effects.empty() ? "(nuisance only)" : fmt::format("{}", fmt::join(fit.effects, " + "));
}

std::string summarize_discovery(const DiscoveryRun& run) {
  const ModelFit& f = run.steps.back().fit;
  return fmt::format("{} after {} step{}: {}, position-error residual {:.3g} rad = {:.3g} arcmin ({:.2f}x floor)",
                     to_string(run.steps.back().verdict), run.steps.size(), run.steps.size() == 1 ? "" : "s",
                     model_name(f), f.residual_rms_rad, rad_to_arcmin(f.residual_rms_rad),
                     f.residual_rms_rad / f.noise_floor_rad);
}

std::vector<std::string> added_effects(const ModelFit& earlier, const ModelFit& later) {
  std::vector<std::string> out;
  for (const auto& e : later.effects) {
    if (std::find(earlier.effects.begin(), earlier.effects.end(), e) == earlier.effects.end()) out.push_back(e);
  }
  return out;
}

std::string step_label(const DiscoveryRun& run, std::size_t step) {
  if (step == 0) return fmt::format("step 1: {}", model_name(run.steps[0].fit));
  return fmt::format("step {}: + {}", step + 1,
                     fmt::join(added_effects(run.steps[step - 1].fit, run.steps[step].fit), " + "));
}

std::string step_color(std::size_t step, std::size_t steps) {
  static constexpr const char* kMiddle[] = {"#e67e22", "#8e44ad", "#16a085", "#b7950b", "#7f8c8d"};
  if (step + 1 == steps) return "#1f5fa8";
  if (step == 0) return "#c0392b";
  return kMiddle[(step - 1) % std::size(kMiddle)];
}

}  // namespace resolver
