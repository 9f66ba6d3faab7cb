// A fleet unit from its logs' statistics (issue 24 item 4): each manifest row's log is
// turned into a statistics file (resolver-model stats' format, stats_file.h) at
//     OUT/UNIT/stats/LINE.stats        LINE: the row's line in the manifest
// or, when that fails, OUT/UNIT/stats/LINE.error holding the reason; then the unit is
// the merge (run_statistics.h merge_runs) of its rows' statistics files read back.
//
// The files are the interface: `resolver-model fleet` writes them itself, or Dask
// workers (tools/python/resolver_bench/fleet.py) and GNU parallel write them with
// `resolver-model stats`, and `fleet --merge-only` merges what is there. Because the
// merge always reads the files (never the in-memory statistics), the two give the
// same unit.json by construction.
#pragma once

#include <string>
#include <vector>

#include "tools/model/fleet.h"

namespace resolver {

/// OUT/UNIT/stats/LINE.stats and OUT/UNIT/stats/LINE.error of a manifest row.
[[nodiscard]] std::string row_stats_path(const std::string& out_dir, const ManifestRow& row);
[[nodiscard]] std::string row_error_path(const std::string& out_dir, const ManifestRow& row);

/// Reads the row's log, fits the fleet's model and writes its statistics file, as
/// `resolver-model stats LOG --out FILE --effects ... --config ...` does; a log that
/// cannot be read or fitted leaves the .error file instead (the other file of the row
/// is removed, so a stale one is never merged). Returns false when the log failed.
bool write_row_statistics(const ManifestRow& row, const std::string& out_dir, const FleetOptions& options);

/// Merges the unit's rows' statistics files into OUT/UNIT/unit.json and
/// calibration.{csv,json,h} (the calibration of the merged parameters). The unit fails,
/// with a unit.json naming every row that failed (its manifest line, log and reason),
/// when any of its rows has no readable statistics, a log is listed twice, a file was
/// made from another log than its row names, or the merge refuses them (pole pairs,
/// signals or model differ). Returns false when the unit failed.
bool merge_unit(const std::string& unit, const std::vector<ManifestRow>& rows, const std::string& manifest,
                const std::string& out_dir, const FleetOptions& options);

}  // namespace resolver
