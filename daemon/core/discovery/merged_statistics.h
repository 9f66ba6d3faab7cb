// Runs' statistics merged (run_statistics.h): each run moved to one point and its own
// constants profiled out, group by group and fold by fold; the chunks of one log share
// its reference zero and envelope gain. The algebra is run_statistics.h's header. Internal to discovery.
#pragma once

#include <cstddef>
#include <span>
#include <string>
#include <vector>

#include "daemon/core/discovery/run_statistics.h"
#include "daemon/core/model/design.h"
#include "daemon/core/model/normal_equations.h"
#include "daemon/core/model/parameter.h"

namespace resolver {

/// Position of `name` in `names`, or -1.
[[nodiscard]] int column_index(const std::vector<std::string>& names, const std::string& name);

/// Every run reduced to the design's columns and added: all rows, and each fold apart
/// (a fold's constants are its own: profiling is not linear in the rows).
struct MergedStatistics {
  std::vector<NormalEquations> all, fold_a, fold_b;  ///< by Group

  explicit MergedStatistics(int columns) {
    for (int g = 0; g < kGroups; ++g) {
      all.emplace_back(columns);
      fold_a.emplace_back(columns);
      fold_b.emplace_back(columns);
    }
  }
};

/// The runs merged as logs: each log's runs (its chunks share its reference zero and gain; a log
/// of one run has only its own constants).
using RunsByLog = std::vector<std::vector<std::size_t>>;

/// `log_of` gives each run's log (empty or negative: a log of its own), as merge_runs.
[[nodiscard]] RunsByLog runs_by_log(std::size_t runs, std::span<const int> log_of);

/// Every run of `runs` moved to the design's point and reduced to its columns, added.
[[nodiscard]] MergedStatistics assemble(const Design& d, const std::vector<RunStatistics>& runs, const RunsByLog& logs);

/// Each run's constants at the solution `s`, named "...[run]"; the position errors' in
/// the log's frame; a log's chunks show its shared constants.
[[nodiscard]] std::vector<ModelParameter> constants_at(const Design& d, const StepSolution& s,
                                                       const std::vector<RunStatistics>& runs,
                                                       const std::vector<std::string>& names, const RunsByLog& logs);

}  // namespace resolver
