// Which effect is missing: every fittable effect not in the model (and every
// custom effect of the config) is a candidate; for the harmonic families, the
// orders the residual asks for (its largest significant orders), not all at once.
// All candidates' columns go into one design with the fitted model, one pass
// accumulates the normal equations, and each "model + candidate" is solved from
// them (one linearised step from the model's solution: exact for linear effects).
// The best nonlinear candidates (delay, tracking loop) are then refitted to
// convergence. Score: BIC; the share of the residual a candidate removes: ERR.
// Candidates the log cannot tell apart (within 10 in BIC: columns that are nearly
// collinear here, e.g. K_2 and offsets without sin/cos) are listed together.
#pragma once

#include <string>
#include <vector>

#include "daemon/core/discovery/model_discovery.h"

namespace resolver {

struct Ranking {
  std::vector<Candidate> candidates;     ///< best first
  std::vector<std::string> not_evaluated;
  int passes = 0;
};

/// Ranks the candidates for the fitted model `fit` on `log`.
[[nodiscard]] Ranking rank_candidates(const PreparedLog& log, const ModelFit& fit, const DiscoveryOptions& options);

/// The two-effect search: the first pair of proposed candidates (best three)
/// that together bring every signal to its floor; empty when none does.
[[nodiscard]] std::vector<std::string> find_missing_pair(const PreparedLog& log, const ModelFit& fit,
                                                         const std::vector<Candidate>& candidates,
                                                         const DiscoveryOptions& options);

}  // namespace resolver
