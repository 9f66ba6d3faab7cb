// resolver-model fleet (issue 24 parts 3-4): a production line's calibrations, one unit
// per folder, and the fleet's summary.
//
//   MANIFEST (CSV "unit,log") ─► per row: the log's statistics (the code `stats` runs)
//       ─► DIR/UNIT/stats/LINE.stats, or DIR/UNIT/stats/LINE.error with the reason
//   per unit: its rows' statistics files merged (fleet_merge.h, merge's code)
//       ─► DIR/UNIT/unit.json + the calibration of the merged parameters (export's formats)
//   DIR/*/unit.json ─► summarize_fleet ─► DIR/fleet.json + a text table ─► DIR/fleet.html (fleet_page.h)
//
// --merge-only skips the first step: the statistics were written elsewhere (Dask workers,
// tools/python/resolver_bench/fleet.py; GNU parallel running `resolver-model stats`).
// The merge reads the files in both cases and the summary reads only the unit.json
// files, so a run on one machine and one whose logs ran elsewhere give the same
// unit.json and fleet.json by construction.
#pragma once

#include <string>
#include <vector>

#include "daemon/app/daemon_config.h"
#include "daemon/core/discovery/model_discovery.h"
#include "daemon/core/model/calibration_table.h"

namespace resolver {

/// One manifest row.
struct ManifestRow {
  std::string unit;
  std::string log;   ///< as resolved: relative paths are relative to the manifest's folder
  std::uint64_t line = 0;
};

/// Reads MANIFEST. Throws std::system_error (exit 3) when it cannot be read and
/// InputError kUsage (exit 2) naming the line when the header is not "unit,log", a row
/// has not two fields or a unit name is not a safe folder name ([A-Za-z0-9_.-], not
/// starting with '.').
[[nodiscard]] std::vector<ManifestRow> read_manifest(const std::string& path);

struct FleetOptions {
  std::vector<std::string> effects;  ///< the model each log is fitted with
  DaemonConfig config;
  DiscoveryOptions discovery;
  int points = 1024;                 ///< calibration table points
  /// The rows' statistics files are already in DIR/UNIT/stats/: only merge and summarize.
  bool merge_only = false;
};

/// Runs every unit of `rows` into out_dir/UNIT/ (stats/ unless merge_only, then
/// unit.json + calibration.{csv,json,h}); a unit that fails gets a unit.json saying why,
/// and a line on stderr naming the unit, the manifest line and the file. Returns the
/// number of units that failed.
int run_fleet_units(const std::vector<ManifestRow>& rows, const std::string& manifest, const std::string& out_dir,
                    const FleetOptions& options);

/// Recomputes out_dir/fleet.json from out_dir/*/unit.json, writes the fleet's page
/// out_dir/fleet.html from them (fleet_page.h) and returns the text table.
/// `failed` is set to the number of units that are not done (including those whose p_r
/// differs from the fleet's).
[[nodiscard]] std::string summarize_fleet(const std::string& out_dir, int& failed);

/// The calibration text in export's formats ("csv", "json", "c-header").
[[nodiscard]] std::string calibration_text(const CalibrationTable& table, const std::string& log,
                                           const std::string& format);

}  // namespace resolver
