#include "tools/model/stats_run.h"

#include <iostream>
#include <stdexcept>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "daemon/app/pipeline.h"
#include "daemon/core/errors.h"
#include "daemon/service/program_version.h"
#include "tools/model/html_report.h"
#include "tools/model/merge_report.h"

namespace resolver {

StatsFile make_stats_file(const LogSamples& samples, const std::string& log, std::span<const std::string> effects,
                          const DiscoveryOptions& options, const DaemonConfig& config) {
  StatsFile file;
  try {
    const PreparedLog prepared = prepare_log(samples.input, options.prepare);
    file.run = run_statistics(prepared, effects, options);
  } catch (const std::invalid_argument& e) {
    throw InputError(Fault::kData, e.what(), Where::at_file(log));
  }
  const LayoutIdentity layout = layout_identity(config);
  file.log = log;
  file.layout_id = layout.id;
  file.layout_description = layout.description;
  file.tool = version_line("resolver-model");
  return file;
}

void write_stats_file(const StatsFile& file, const std::string& out) {
  const std::string text = format_stats_file(file);
  write_text_file(out, text);  // throws std::system_error: exit 3
  const RunStatistics& r = file.run;
  std::cout << fmt::format("wrote {} ({} KiB): {} fitted samples of {}, model {}, {} columns ({} the candidates')\n",
                           out, (text.size() + 512) / 1024, r.fitted_rows, file.log, fmt::join(r.effects, ","),
                           r.columns.size(), r.columns.size() - static_cast<std::size_t>(r.nuisance_columns + r.model_columns));
}

int run_merge(const std::vector<std::string>& paths, std::span<const std::string> effects, bool json,
              const DiscoveryOptions& options) {
  std::vector<StatsFile> files;
  std::vector<RunStatistics> runs;
  for (const std::string& p : paths) {
    files.push_back(read_stats_file(p));
    runs.push_back(files.back().run);
  }
  check_same_layout(files, paths);
  MergedFit merged;
  try {
    merged = merge_runs(runs, paths, effects, options);
  } catch (const std::invalid_argument& e) {
    throw InputError(Fault::kData, e.what());
  }
  std::cout << (json ? format_merge_json(merged, paths, runs, options.explained_ratio)
                     : format_merge_text(merged, paths, runs, options.explained_ratio));
  return 0;
}

}  // namespace resolver
