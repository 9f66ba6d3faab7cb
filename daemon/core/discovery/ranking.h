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

#include <map>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "daemon/core/discovery/model_discovery.h"
#include "daemon/core/model/design.h"
#include "daemon/core/model/least_squares.h"

namespace resolver {

/// Two candidates and what their joint linearised step leaves (screen_pairs).
struct ScreenedPair {
  std::string a, b;
  double weighted_rss = 0.0;  ///< each signal over its floor squared
};

struct Ranking {
  std::vector<Candidate> candidates;     ///< best first
  std::vector<std::string> not_evaluated;
  int passes = 0;
  /// Pairs of the first proposed candidates (effects, not families; none in place of a model
  /// term), the pair whose joint linearised step leaves the least weighted residual first:
  /// the two-effect search's last resort (find_missing_pair).
  std::vector<ScreenedPair> screened_pairs;
};

/// What the log's motion (or signals) lacks for `e` to be identifiable, as advice
/// ("" = nothing): a speed change, a reversal, or sin/cos beside the R/D angle (`sincos`).
[[nodiscard]] std::string motion_missing(const Effect& e, const MotionSummary& m, bool sincos);

/// One sentence of the term's physics with its values, said to be its fit or (`one_step`)
/// one linearised step from zero (Candidate::stepped).
[[nodiscard]] std::string reason_of(const ModelTerm& t, const std::vector<ModelParameter>& params, bool one_step = false);

/// The parameters of `design`'s term in value coordinates with standard errors from `s`.
/// `step` moves the term by the solution first (a linearised candidate taken from its
/// neutral point); without it the design is already at the solution (a converged refit).
[[nodiscard]] std::vector<ModelParameter> term_params(const Design& design, std::size_t term, const StepSolution& s,
                                                      bool step);

/// What a candidate's step `s` leaves against the model's `base`: residuals (`rd`: the
/// position error is the R/D angle's), BIC drop, the share of the model's weighted
/// residual it removes, whether it is proposed and reaches the floor.
void score_candidate(Candidate& c, const StepSolution& s, bool rd, const StepSolution& base, const GroupFloors& floors,
                     const DiscoveryOptions& options);

/// The linearised step of a candidate with parameters `t` (columns `term_cols`, one per
/// parameter) on the model's columns `base_cols`. Part of a multi-parameter candidate
/// may be the model's already (a 2 theta_m order at p_r = 1 without sin/cos: its sin
/// part is alpha's): then each parameter alone is tried and the best the statistics
/// separate kept (`t` narrowed to it). The same rule on a log and on merged statistics.
[[nodiscard]] StepSolution solve_candidate(const std::vector<NormalEquations>& groups, const GroupFloors& floors,
                                           const std::vector<int>& base_cols, std::span<const int> term_cols,
                                           ModelTerm& t);

/// Whether a candidate's linearised score is not its fit: an envelope effect (through
/// atan2) whose step does not already reach the floor, or one with a nonlinear parameter
/// (delay, tracking loop); offline (DiscoveryOptions::refit_proposed) every proposed
/// one. Such candidates are refitted to convergence with the model.
[[nodiscard]] bool needs_exact_refit(const Candidate& c, const DiscoveryOptions& options);

/// Sets Candidate::stepped (not refitted, and its step is not its fit: needs_exact_refit)
/// and says so in its reason, so no report calls one step a fit.
void flag_one_step(Candidate& c, const DiscoveryOptions& options);

/// The effects of `ranked` (best first) to refit so: the best kNonlinearRefits proposed
/// ones that need it. The same rule for a log in memory and for merged statistics.
[[nodiscard]] std::vector<std::string> exact_refits(const std::vector<Candidate>& ranked, const DiscoveryOptions& options);

/// The candidate terms effects ask for from the fit's residual (Effect::residual_candidates:
/// the harmonic orders of the residual, each alone, with its quadrature part, and every
/// significant order as a family), before the log's checks; the model's own parameters
/// are left out. `answered` (may be null) gets each effect that answered.
[[nodiscard]] std::vector<ModelTerm> residual_candidate_terms(const ModelFit& fit, const DiscoveryOptions& opt,
                                                              std::vector<const Effect*>* answered = nullptr);

/// A harmonic family: every significant order at once (named first only alone).
[[nodiscard]] bool is_family(const ModelTerm& t);

/// Whether `effect` is already among `candidates`. Without sin/cos a pair whose columns the
/// R/D angle cannot separate keeps its better one (solve_candidate): harmonics and
/// harmonics(k3,k3_q) can both become harmonics(k3_q). Listed twice, such a term took two of
/// the exact refits' places and pushed the third candidate (the true one, a tracking loop)
/// out of them: it is scored once, in memory and in a merge.
[[nodiscard]] bool already_listed(const std::vector<Candidate>& candidates, const std::string& effect);

/// explain's order of scored candidates: best BIC first, candidates the log cannot tell
/// apart simplest first (fits_as_well), a family first only when nothing smaller does.
void order_ranked(std::vector<Candidate>& candidates, const DiscoveryOptions& options);

/// Ranking::screened_pairs: each pair of the best proposed candidates of `ranked` (effects,
/// not families, none in place of a model term), its joint linearised step solved from
/// `groups` (the normal equations of the model's `base_cols` and every candidate's
/// `columns_of`: no pass over the rows, 28 small solves). Pairs far behind the best, or
/// little better than the best candidate alone, are left out. Linearised, so only an order
/// of which pairs to fit exactly: at real magnitudes an envelope effect's step from zero
/// leaves its second-order terms far above the floor. The same on a log and on merged
/// statistics.
[[nodiscard]] std::vector<ScreenedPair> screen_pairs(
    const std::vector<Candidate>& ranked, const std::map<std::string, std::vector<int>>& columns_of,
    const std::vector<NormalEquations>& groups, const GroupFloors& floors, const std::vector<int>& base_cols);

/// Ranks the candidates for the fitted model `fit` on `log`.
[[nodiscard]] Ranking rank_candidates(const PreparedLog& log, const ModelFit& fit, const DiscoveryOptions& options);

/// The two-effect search: the first pair of proposed candidates that together bring
/// every signal to its floor; empty when none does. The best three are paired first;
/// then, where the log cannot tell candidates apart (fits_as_well: the best three may be
/// one class of aliases), the first members of the three best classes across classes;
/// then the best `screened` pairs (Ranking::screened_pairs) not tried yet. With
/// PairSearch::kScreened only those: a best candidate is named already, and the search asks
/// only whether the pair the screen puts first does better (one fit, more only where the
/// next pairs tie with it: fits_next_screened).
enum class PairSearch { kEvery, kScreened };

/// Whether a two-effect search that has fitted `fits` screened pairs, the first leaving
/// `first_rss`, fits the next one, leaving `rss` linearised: at most 3; with
/// PairSearch::kScreened 1, and beyond it only pairs the screen cannot order against the
/// first (within 5 % of its residual). The same rule on a log and on merged statistics.
[[nodiscard]] bool fits_next_screened(int fits, PairSearch search, double rss, double first_rss);

[[nodiscard]] std::vector<std::string> find_missing_pair(const PreparedLog& log, const ModelFit& fit,
                                                         const std::vector<Candidate>& candidates,
                                                         const DiscoveryOptions& options,
                                                         std::span<const ScreenedPair> screened = {},
                                                         PairSearch search = PairSearch::kEvery);

}  // namespace resolver
