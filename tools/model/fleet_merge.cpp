#include "tools/model/fleet_merge.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <new>
#include <sstream>
#include <system_error>

#include "daemon/core/health/signal_health.h"
#include "daemon/core/model/model.h"
#include "tools/model/html_report.h"
#include "tools/model/json_text.h"
#include "tools/model/log_samples.h"
#include "tools/model/merge_report.h"
#include "tools/model/stats_run.h"

namespace resolver {

namespace fs = std::filesystem;

namespace {

std::string stats_dir(const std::string& out_dir, const std::string& unit) { return out_dir + "/" + unit + "/stats"; }

/// The statistics `resolver-model stats LOG` takes (main's statistics_of_log without
/// --chunk or a slice): the same library calls, so the files are the same bytes.
StatsFile log_statistics(const std::string& log, const FleetOptions& o) {
  if (!fs::exists(log)) throw std::system_error(std::make_error_code(std::errc::no_such_file_or_directory), log);
  const LogSamples samples = read_log_samples(log, {}, o.config);
  DiscoveryOptions options = o.discovery;
  options.untrusted_input = lasting_faults(fault_counts(samples), samples.health_samples, kUntrustedFaultShare);
  StatsFile file = stats_file_header(log, o.config);
  add_run(file, log, samples.input, o.effects, options);
  mark_untrusted(file, options.untrusted_input);
  file.input = input_notes(samples);
  return file;
}

std::string read_text(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  std::string s = text.str();
  while (!s.empty() && (s.back() == '\n' || s.back() == '\r')) s.pop_back();
  return s;
}

bool same_file(const std::string& a, const std::string& b) {
  std::error_code ea, eb;
  const fs::path ca = fs::weakly_canonical(a, ea), cb = fs::weakly_canonical(b, eb);
  return ea || eb ? a == b : ca == cb;
}

/// One manifest row of the unit: its statistics read back, or why there are none.
struct RowResult {
  const ManifestRow* row = nullptr;
  StatsFile file;
  std::string error;  ///< empty: `file` holds its statistics
};

RowResult read_row(const ManifestRow& row, const std::string& out_dir) {
  RowResult r;
  r.row = &row;
  const std::string stats = row_stats_path(out_dir, row), error = row_error_path(out_dir, row);
  if (fs::exists(stats)) {
    try {
      r.file = read_stats_file(stats);
    } catch (const std::bad_alloc&) {
      throw;
    } catch (const std::exception& e) {
      r.error = fmt::format("its statistics {} are unreadable: {}", stats, e.what());
      return r;
    }
    // A file left from another manifest whose line LINE named another log is not this row's.
    if (!same_file(r.file.log, row.log)) {
      r.error = fmt::format("{} was made from {}, not from this row's log", stats, r.file.log);
    } else if (r.file.runs.empty()) {
      r.error = fmt::format("{} holds no run", stats);
    }
  } else if (fs::exists(error)) {
    r.error = read_text(error);
    if (r.error.empty()) r.error = error + " is empty: the statistics failed without a reason";
  } else {
    r.error = fmt::format("no statistics: neither {} nor {} exists (resolver-model stats was not run for this row, "
                          "or its job was lost)",
                          stats, error);
  }
  return r;
}

/// Problems that fail the unit before its statistics are read: a log listed twice
/// (however spelt) would count twice in the merge.
std::vector<std::string> duplicate_logs(const std::string& unit, const std::vector<ManifestRow>& rows,
                                        const std::string& manifest) {
  std::vector<std::string> problems;
  std::map<std::string, std::uint64_t> seen;
  for (const auto& r : rows) {
    std::error_code ec;
    const std::string key = fs::weakly_canonical(r.log, ec).string();
    const auto [it, fresh] = seen.emplace(ec ? r.log : key, r.line);
    if (!fresh) {
      problems.push_back(fmt::format("{}:{}: log {} is listed twice for unit {} (also line {})", manifest, r.line,
                                     r.log, unit, it->second));
    }
  }
  return problems;
}

std::string strings_json(const std::vector<std::string>& v) {
  std::string o = "[";
  for (std::size_t i = 0; i < v.size(); ++i) o += (i ? "," : "") + json::str(v[i]);
  return o + "]";
}

std::string params_json(const std::vector<ModelParameter>& params) {
  std::string o = "{";
  for (std::size_t i = 0; i < params.size(); ++i) {
    o += (i ? "," : "") + json::str(params[i].name) + ":{\"value\":" + json::num(params[i].value) +
         ",\"stderr\":" + json::num(params[i].std_error) + ",\"unit\":" + json::str(params[i].unit) + "}";
  }
  return o + "}";
}

/// unit.json's "logs": every row with its line, its statistics file and its own fit
/// (the values the merge compares it by), or its reason.
std::string logs_json(const std::vector<RowResult>& rows) {
  std::string o = "[";
  for (const RowResult& r : rows) {
    o += fmt::format("{}{{\"log\":{},\"line\":{},\"stats\":{}", o.size() > 1 ? "," : "", json::str(r.row->log),
                     r.row->line, json::str(fmt::format("stats/{}.stats", r.row->line)));
    if (!r.error.empty()) {
      o += ",\"status\":\"failed\",\"reason\":" + json::str(r.error) + "}";
      continue;
    }
    std::int64_t rows_fitted = 0;
    for (const NamedRun& n : r.file.runs) rows_fitted += n.run.fitted_rows;
    const RunStatistics& run = r.file.runs.front().run;
    o += fmt::format(",\"status\":\"done\",\"p_r\":{},\"p\":{},\"runs\":{},\"fitted_samples\":{},\"effects\":{},"
                     "\"params\":{}}}",
                     run.layout.p_r, run.layout.p, r.file.runs.size(), rows_fitted, strings_json(run.effects),
                     params_json(run.params));
  }
  return o + "]";
}

void write_failed_unit(const std::string& dir, const std::string& unit, const std::string& reason,
                       std::size_t log_rows, const std::string& logs) {
  write_text_file(dir + "/unit.json",
                  fmt::format("{{\"unit\":{},\"status\":\"failed\",\"reason\":{},\"log_rows\":{},\"logs\":{}}}\n",
                              json::str(unit), json::str(reason), log_rows, logs));
}

/// The position-error signal's residual and floor (the first signal's without an R/D angle).
std::pair<double, double> residual_and_floor(const MergedFit& m) {
  const auto it = std::find_if(m.signals.begin(), m.signals.end(),
                               [](const SignalResidual& s) { return s.signal == "position_error"; });
  if (it != m.signals.end()) return {it->rms, it->floor};
  if (!m.signals.empty()) return {m.signals.front().rms, m.signals.front().floor};
  return {std::nan(""), std::nan("")};
}

/// unit.json's fit fields, the keys the single-log fleet wrote (summarize_fleet reads them).
std::string fit_fields(const MergedFit& m, const MergeVerdict& v) {
  std::vector<std::string> proposed;
  for (const Candidate& c : m.candidates) {
    if (c.proposed) proposed.push_back(c.effect);
  }
  const auto [rms, floor_rad] = residual_and_floor(m);
  return fmt::format(
      "\"verdict\":{},\"summary\":{},\"residual_rms_rad\":{},\"noise_floor_rad\":{},\"residual_over_floor\":{},"
      "\"effects\":{},\"params\":{},\"proposed\":{},\"notes\":{}",
      json::str(v.word), json::str(v.summary), json::num(rms), json::num(floor_rad), json::num(rms / floor_rad),
      strings_json(m.effects), params_json(m.params), strings_json(proposed), strings_json(m.notes));
}

/// The merge's comparisons beyond kPoolDisagreementZ: each run's own fit against the
/// unit's other runs'. `names` gets the parameters they disagree on.
std::string disagreements_json(const MergedFit& m, std::vector<std::string>& names) {
  std::string o = "[";
  for (const PoolDisagreement& d : m.comparisons) {
    if (!(std::abs(d.z) > kPoolDisagreementZ)) continue;
    if (std::find(names.begin(), names.end(), d.parameter) == names.end()) names.push_back(d.parameter);
    o += (o.size() > 1 ? "," : "") +
         fmt::format("{{\"param\":{},\"log\":{},\"value\":{},\"others\":{},\"others_stderr\":{},\"z\":{}}}",
                     json::str(d.parameter), json::str(d.log), json::num(d.value), json::num(d.others),
                     json::num(d.others_std_error), json::num(d.z, 4));
  }
  return o + "]";
}

/// The calibration of the merged parameters: the fleet's model at the merge's values
/// (the others neutral), tabulated as `export` does.
CalibrationTable merged_table(const MergedFit& m, const PoolLayout& layout, const FleetOptions& o) {
  Model model(ModelSpec::parse(m.effects, o.config.model.customs.get()), layout.p_r, layout.p);
  model.keep(o.config.model.customs);
  for (const ModelParameter& p : m.params) model.set(p.name, p.value, p.std_error);
  return tabulate(model, o.points);
}

/// The unit's runs, each named by its row's log (a chunked file's runs by log and span,
/// as merge names them); `notes` gets what the statistics left out and the reader counted.
void collect_runs(const std::vector<RowResult>& rows, std::vector<RunStatistics>& runs, std::vector<std::string>& names,
                  std::vector<int>& log_of, std::vector<std::string>& notes) {
  for (const RowResult& r : rows) {
    for (const NamedRun& n : r.file.runs) {
      names.push_back(r.file.runs.size() == 1 ? r.row->log : r.row->log + ": " + n.name.substr(n.name.rfind(" [") + 1));
      runs.push_back(n.run);
      log_of.push_back(static_cast<int>(&r - rows.data()));  // a file's runs are one log's chunks
    }
    for (const std::string& l : r.file.left_out) notes.push_back("left out when the statistics were made: " + l);
    for (const std::string& n : r.file.input) notes.push_back(r.row->log + ": " + n);
  }
}

/// Writes the done unit's calibration files and unit.json.
void write_done_unit(const std::string& dir, const std::string& unit, const std::vector<RowResult>& rows,
                     const MergedFit& m, const PoolLayout& layout, const FleetOptions& o) {
  std::vector<std::string> logs;
  logs.reserve(rows.size());
  for (const RowResult& r : rows) logs.push_back(r.row->log);
  const std::string origin = fmt::format("{}", fmt::join(logs, " + "));
  const CalibrationTable table = merged_table(m, layout, o);
  write_text_file(dir + "/calibration.csv", calibration_text(table, origin, "csv"));
  write_text_file(dir + "/calibration.json", calibration_text(table, origin, "json"));
  write_text_file(dir + "/calibration.h", calibration_text(table, origin, "c-header"));
  const MergeVerdict v = merge_verdict(m, o.discovery.explained_ratio);
  const std::string needed =
      v.word == "missing_effect" && !m.candidates.empty() ? json::str(m.candidates.front().effect) : "null";
  std::vector<std::string> disagreeing;
  const std::string disagreements = disagreements_json(m, disagreeing);
  // calibration_log (the single-log fleet's key) is the first log; the calibration is of
  // every log merged (calibration_logs).
  write_text_file(dir + "/unit.json",
                  fmt::format("{{\"unit\":{},\"status\":\"done\",\"calibration_log\":{},\"calibration_logs\":{},"
                              "\"merged_logs\":{},\"merged_runs\":{},\"p_r\":{},\"p\":{},{},\"needed\":{},"
                              "\"disagreeing\":{},\"disagreements\":{},\"log_rows\":{},"
                              "\"files\":[\"calibration.csv\",\"calibration.json\",\"calibration.h\"],\"logs\":{}}}\n",
                              json::str(unit), json::str(logs.front()), strings_json(logs), logs.size(), m.runs,
                              layout.p_r, layout.p,
                              fit_fields(m, v), needed, strings_json(disagreeing), disagreements, rows.size(),
                              logs_json(rows)));
  if (!disagreeing.empty()) {
    std::cerr << "resolver-model fleet: unit " << unit << ": its logs disagree on "
              << fmt::format("{}", fmt::join(disagreeing, ", "))
              << " (a log's own fit beyond 4 standard errors of the unit's other logs; unit.json: disagreements)\n";
  }
}

}  // namespace

std::string row_stats_path(const std::string& out_dir, const ManifestRow& row) {
  return fmt::format("{}/{}.stats", stats_dir(out_dir, row.unit), row.line);
}

std::string row_error_path(const std::string& out_dir, const ManifestRow& row) {
  return fmt::format("{}/{}.error", stats_dir(out_dir, row.unit), row.line);
}

bool write_row_statistics(const ManifestRow& row, const std::string& out_dir, const FleetOptions& options) {
  const std::string stats = row_stats_path(out_dir, row), error = row_error_path(out_dir, row);
  fs::create_directories(stats_dir(out_dir, row.unit));
  StatsFile file;
  std::string reason;
  try {
    file = log_statistics(row.log, options);
  } catch (const std::bad_alloc&) {
    throw;  // out of memory is the whole run's problem (exit 4), not one log's
  } catch (const std::system_error& e) {
    reason = std::string("cannot read the log: ") + e.what();
  } catch (const std::exception& e) {
    reason = e.what();
  }
  // Exactly one of the row's two files is left: a stale one is never merged.
  fs::remove(reason.empty() ? error : stats);
  if (!reason.empty()) {
    write_text_file(error, reason + "\n");
    return false;
  }
  write_text_file(stats, format_stats_file(file));  // a failed write is the run's problem (exit 3)
  return true;
}

bool merge_unit(const std::string& unit, const std::vector<ManifestRow>& rows, const std::string& manifest,
                const std::string& out_dir, const FleetOptions& o) {
  const std::string dir = out_dir + "/" + unit;
  fs::create_directories(dir);
  for (const char* stale : {"unit.json", "calibration.csv", "calibration.json", "calibration.h"}) {
    fs::remove(dir + "/" + stale);  // a unit that fails now leaves no calibration of an earlier run
  }
  std::vector<std::string> problems = duplicate_logs(unit, rows, manifest);
  std::vector<RowResult> results;
  for (const ManifestRow& r : rows) {
    results.push_back(read_row(r, out_dir));
    if (!results.back().error.empty()) {
      problems.push_back(fmt::format("{} (manifest line {}): {}", r.log, r.line, results.back().error));
    }
  }
  std::vector<RunStatistics> runs;
  std::vector<std::string> names, file_notes;
  std::vector<int> log_of;
  MergedFit merged;
  if (problems.empty()) {
    collect_runs(results, runs, names, log_of, file_notes);
    try {
      merged = merge_runs(runs, names, o.effects, o.discovery, log_of);
    } catch (const std::invalid_argument& e) {
      problems.push_back(std::string("its logs' statistics do not merge: ") + e.what());
    }
  }
  if (!problems.empty()) {
    const std::string reason = fmt::format("{}", fmt::join(problems, "; "));
    std::cerr << "resolver-model fleet: unit " << unit << " failed: " << reason << "\n";
    write_failed_unit(dir, unit, reason, rows.size(), logs_json(results));
    return false;
  }
  merged.notes.insert(merged.notes.end(), file_notes.begin(), file_notes.end());
  write_done_unit(dir, unit, results, merged, runs.front().layout, o);
  return true;
}

}  // namespace resolver
