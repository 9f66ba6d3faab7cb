// Shared steps of fit, ranking and narration: the nuisance columns a log needs,
// the columns of a design's model, residual rms per signal, the verdict test.
#pragma once

#include <array>
#include <span>
#include <string>
#include <vector>

#include "daemon/core/discovery/model_discovery.h"
#include "daemon/core/model/least_squares.h"

namespace resolver {

/// SignalResidual::signal of each group (least_squares.h Group).
inline constexpr std::array<const char*, kGroups> kGroupSignals{"position_error", "sin_cos", "i_dq"};

/// Why a mounting offset cannot be fitted against an unaligned reference.
inline constexpr std::string_view kNeedsAlignedReference =
    "a constant position error against the reference is the reference's own zero unless that zero is set on the "
    "rotor d axis: [bench] reference_aligned = true (resolver-model --reference-aligned)";

/// The nuisance columns of a log: constants the true angle cannot give (no
/// reference), the envelopes' amplitude, the dq operating point.
[[nodiscard]] std::vector<Nuisance> nuisances_for(const PreparedLog& log);

/// The design of `model` at its values for `log`: its nuisances, one set per pooled
/// part (a model fitted to the same parts keeps each part's frame shift).
[[nodiscard]] Design design_for(const Model& model, const PreparedLog& log);

/// Nuisance and model (non-candidate) columns of a design.
[[nodiscard]] std::vector<int> model_columns(const Design& design);

/// Columns of design term `term` (all of its fitted parameters).
[[nodiscard]] std::vector<int> term_columns(const Design& design, std::size_t term);

/// Where the design's model is not separable at its point (one pass over `rows`): the
/// model terms without any one of which the rest are. Such terms are aliases of one
/// another at first order (a mechanical harmonic at a whole electrical order lands on the
/// same sin/cos and angle as the winding terms of that order), told apart only by their
/// second-order terms, if at all. Empty where the model is separable there, or where
/// leaving out no single term makes it so.
[[nodiscard]] std::vector<std::size_t> aliased_terms(const Design& design, std::span<const FitRow> rows,
                                                     const GroupFloors& floors);

/// sqrt(rss / n), 0 for n = 0.
[[nodiscard]] double rms(double rss, std::int64_t n);

/// Every fitted group's residual (from a solution) within ratio x its floor.
[[nodiscard]] bool groups_explained(const StepSolution& s, const GroupFloors& floors, double ratio);

/// BIC of a solution: n ln(RSS_w / n) + k ln n over every weighted row.
[[nodiscard]] double bic_of(const StepSolution& s);

/// Checks the model's needs against the log (reference, currents, coverage).
/// Throws std::invalid_argument naming the effect and what the log lacks.
void check_model_against_log(const ModelSpec& spec, const PreparedLog& log);

/// Cross-validated rms of group g: each fold fitted on `cols` and evaluated on the
/// other (NaN without two folds).
[[nodiscard]] double held_back_rms(const PassStatistics& stats, const GroupFloors& floors, std::span<const int> cols,
                                   Group g);
/// The same from each fold's statistics by group (a merge's, whose folds are reduced apart).
[[nodiscard]] double held_back_rms(const std::vector<NormalEquations>& fold_a,
                                   const std::vector<NormalEquations>& fold_b, const GroupFloors& floors,
                                   std::span<const int> cols, Group g);

/// "%.3g" formatting for messages.
[[nodiscard]] std::string num(double v, const char* format = "%.3g");

/// Standard error of a polar pair's amplitude or phase (parameter `p` of `t`: Polar::
/// kAmplitude or kPhase; the design fits their Cartesian x and y) from the covariance
/// `cov_xy` of x and y, at the term's values: the Jacobian of (x, y) -> (e, phase). The
/// phase's is the Cartesian one over e (NaN at e = 0: no phase to speak of).
[[nodiscard]] double polar_std_error(const DesignTerm& t, std::size_t p, const Eigen::Matrix2d& cov_xy);

}  // namespace resolver
