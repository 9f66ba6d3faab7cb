#include "tools/model/fleet.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cmath>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>
#include <system_error>

#include "daemon/service/program_errors.h"
#include "daemon/service/table_file.h"
#include "tools/model/fleet_merge.h"
#include "tools/model/fleet_page.h"
#include "tools/model/html_report.h"
#include "tools/model/json_text.h"
#include "tools/model/json_value.h"

namespace resolver {

namespace fs = std::filesystem;

namespace {

std::string trim(std::string s) {
  const auto not_space = [](unsigned char c) { return !std::isspace(c); };
  s.erase(s.begin(), std::find_if(s.begin(), s.end(), not_space));
  s.erase(std::find_if(s.rbegin(), s.rend(), not_space).base(), s.end());
  return s;
}

bool safe_unit_name(const std::string& u) {
  if (u.empty() || u.front() == '.' || u.size() > 128) return false;
  return std::all_of(u.begin(), u.end(), [](unsigned char c) { return std::isalnum(c) || c == '_' || c == '-' || c == '.'; });
}

std::string strings_json(const std::vector<std::string>& v) {
  std::string o = "[";
  for (std::size_t i = 0; i < v.size(); ++i) o += (i ? "," : "") + json::str(v[i]);
  return o + "]";
}

// ---- the summary ------------------------------------------------------------------

/// Linear interpolation between order statistics (numpy's default).
double quantile(const std::vector<double>& sorted, double q) {
  if (sorted.empty()) return std::nan("");
  const double pos = q * static_cast<double>(sorted.size() - 1);
  const auto lo = static_cast<std::size_t>(std::floor(pos));
  const std::size_t hi = std::min(lo + 1, sorted.size() - 1);
  return sorted[lo] + (pos - static_cast<double>(lo)) * (sorted[hi] - sorted[lo]);
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return quantile(v, 0.5);
}

struct UnitSummary {
  std::string unit;
  bool done = false;
  std::string reason;
  int p_r = 0;
  std::string verdict, needed;
  double ratio = 0.0;
  std::vector<std::string> proposed, disagreeing;
  std::vector<std::pair<std::string, double>> params;
  std::map<std::string, double> std_errors;  ///< of params (NaN: none)
  std::size_t logs = 0;
};

UnitSummary read_unit(const fs::path& file) {
  UnitSummary u;
  u.unit = file.parent_path().filename().string();
  std::ifstream in(file);
  std::stringstream text;
  text << in.rdbuf();
  try {
    const json::Json j = json::parse_json(trim(text.str()));
    u.logs = static_cast<std::size_t>(j["log_rows"].integer());
    if (j["status"].text != "done") {
      u.reason = j.has("reason") ? j["reason"].text : "failed";
      return u;
    }
    u.p_r = static_cast<int>(j["p_r"].integer());
    u.verdict = j["verdict"].text;
    u.ratio = j["residual_over_floor"].is_null() ? std::nan("") : j["residual_over_floor"].number();
    u.needed = j["needed"].is_null() ? "" : j["needed"].text;
    for (const auto& e : j["proposed"].items) u.proposed.push_back(e.text);
    for (const auto& e : j["disagreeing"].items) u.disagreeing.push_back(e.text);
    for (const auto& [name, p] : j["params"].members) {
      u.params.emplace_back(name, p["value"].number());
      u.std_errors[name] = p["stderr"].is_null() ? std::nan("") : p["stderr"].number();
    }
    u.done = true;
  } catch (const std::exception& e) {
    u.reason = fmt::format("{}: unreadable ({})", file.string(), e.what());
  }
  return u;
}

/// Every DIR/*/unit.json (hidden folders skipped), in the order of their paths.
std::vector<UnitSummary> read_units(const std::string& out_dir) {
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(out_dir)) {
    const std::string name = entry.path().filename().string();
    if (entry.is_directory() && !name.empty() && name.front() != '.' && fs::exists(entry.path() / "unit.json")) {
      files.push_back(entry.path() / "unit.json");
    }
  }
  std::sort(files.begin(), files.end());
  std::vector<UnitSummary> units;
  for (const auto& f : files) units.push_back(read_unit(f));
  return units;
}

/// The fleet's p_r and how many units have it.
struct FleetPolePairs {
  int p_r = 0;
  int units = 0;
};

/// The fleet's p_r: the most common among the units done; a unit with another is left out.
FleetPolePairs leave_out_other_p_r(std::vector<UnitSummary>& units) {
  std::map<int, int> p_r_count;
  for (const auto& u : units) {
    if (u.done) ++p_r_count[u.p_r];
  }
  FleetPolePairs fleet;
  for (const auto& [p_r, count] : p_r_count) {
    if (count > fleet.units) fleet.p_r = p_r, fleet.units = count;
  }
  for (auto& u : units) {
    if (u.done && u.p_r != fleet.p_r) {
      u.done = false;
      u.reason = fmt::format("its logs have p_r = {}, the fleet's is {} ({} units): left out of the summary", u.p_r,
                             fleet.p_r, fleet.units);
    }
  }
  return fleet;
}

/// What the units done have in common: each parameter's values, the effects proposed
/// and needed, and the logs counted and left out.
struct FleetTally {
  std::size_t logs_total = 0, logs_left_out = 0;
  std::map<std::string, std::vector<double>> values;  // per parameter, over the units done
  std::map<std::string, int> proposed, needed;
  int done = 0;
};

FleetTally tally_units(const std::vector<UnitSummary>& units) {
  FleetTally t;
  for (const auto& u : units) {
    t.logs_total += u.logs;
    if (!u.done) {
      t.logs_left_out += u.logs;
      continue;
    }
    for (const auto& [name, v] : u.params) t.values[name].push_back(v);
    for (const auto& e : u.proposed) ++t.proposed[e];
    if (!u.needed.empty()) ++t.needed[u.needed];
  }
  t.done = static_cast<int>(std::count_if(units.begin(), units.end(), [](const UnitSummary& u) { return u.done; }));
  return t;
}

struct ParamStat {
  double median, spread;
};

/// Per parameter: median, robust spread (1.4826 MAD) and quantiles, as fleet.json's
/// "params" and as the text table.
struct ParamSummary {
  std::map<std::string, ParamStat> stats;
  std::string json, table;
};

ParamSummary summarize_params(const std::map<std::string, std::vector<double>>& values) {
  ParamSummary s;
  s.json = "{";
  s.table = fmt::format("{:<36} {:>5} {:>12} {:>11} {:>12} {:>12}\n", "parameter", "units", "median", "spread", "q05",
                        "q95");
  for (const auto& [name, unsorted] : values) {
    std::vector<double> v = unsorted;
    std::sort(v.begin(), v.end());
    const double med = quantile(v, 0.5);
    std::vector<double> dev;
    for (double x : v) dev.push_back(std::abs(x - med));
    const double spread = 1.4826 * median(dev);
    s.stats[name] = {med, spread};
    s.json += (s.json.size() > 1 ? "," : "") +
              fmt::format("{}:{{\"units\":{},\"median\":{},\"spread\":{},\"q05\":{},\"q25\":{},\"q75\":{},\"q95\":{},"
                          "\"min\":{},\"max\":{}}}",
                          json::str(name), v.size(), json::num(med), json::num(spread), json::num(quantile(v, 0.05)),
                          json::num(quantile(v, 0.25)), json::num(quantile(v, 0.75)), json::num(quantile(v, 0.95)),
                          json::num(v.front()), json::num(v.back()));
    s.table += fmt::format("{:<36} {:>5} {:>12.5g} {:>11.3g} {:>12.5g} {:>12.5g}\n", name, v.size(), med, spread,
                           quantile(v, 0.05), quantile(v, 0.95));
  }
  s.json += "}";
  return s;
}

/// The outlier units, as fleet.json's "outliers" and as text lines.
struct FleetOutliers {
  std::string json, lines;
};

/// Units outside the spread: |value - median| > 4 robust spreads, with the parameter
/// (only where the spread is > 0 over at least 3 units), and by more than 3 of the
/// unit's own standard errors: units that agree to a few microradians have a spread
/// of their noise, and a unit 4 such spreads out is not odd when its own error covers
/// it (a 20-unit run flagged a beta of -4.5e-6 rad before).
FleetOutliers find_outliers(const std::vector<UnitSummary>& units, const ParamSummary& params,
                            const std::map<std::string, std::vector<double>>& values) {
  FleetOutliers o;
  o.json = "[";
  for (const auto& u : units) {
    if (!u.done) continue;
    for (const auto& [name, v] : u.params) {
      const ParamStat& s = params.stats.at(name);
      if (!(s.spread > 0.0) || values.at(name).size() < 3) continue;
      const double z = (v - s.median) / s.spread;
      if (std::abs(z) <= 4.0) continue;
      const auto se = u.std_errors.find(name);
      if (se != u.std_errors.end() && std::isfinite(se->second) && std::abs(v - s.median) <= 3.0 * se->second) continue;
      o.json += (o.json.size() > 1 ? "," : "") + fmt::format("{{\"unit\":{},\"param\":{},\"value\":{},\"z\":{}}}",
                                                             json::str(u.unit), json::str(name), json::num(v),
                                                             json::num(z, 4));
      o.lines += fmt::format("outlier: unit {} {} = {:.5g} (robust z {:+.1f})\n", u.unit, name, v, z);
    }
  }
  o.json += "]";
  return o;
}

/// Effects by how many units name them, most first: fleet.json's "proposed" and "needed".
std::string effect_counts_json(const std::map<std::string, int>& m, int done) {
  std::vector<std::pair<std::string, int>> v(m.begin(), m.end());
  std::stable_sort(v.begin(), v.end(), [](const auto& a, const auto& b) { return a.second > b.second; });
  std::string o = "[";
  for (const auto& [e, n] : v) {
    o += (o.size() > 1 ? "," : "") + fmt::format("{{\"effect\":{},\"units\":{},\"most_units\":{}}}", json::str(e), n,
                                                 2 * n > done ? "true" : "false");
  }
  return o + "]";
}

/// The units done (fleet.json's "units") and the failed ones with the reason (its
/// "failed" and text lines).
struct UnitLists {
  std::string units_json, failed_json, failed_lines;
};

UnitLists list_units(const std::vector<UnitSummary>& units) {
  UnitLists l{"[", "[", ""};
  for (const auto& u : units) {
    if (!u.done) {
      l.failed_json += (l.failed_json.size() > 1 ? "," : "") +
                       fmt::format("{{\"unit\":{},\"reason\":{}}}", json::str(u.unit), json::str(u.reason));
      l.failed_lines += fmt::format("failed: unit {}: {}\n", u.unit, u.reason);
      continue;
    }
    l.units_json += (l.units_json.size() > 1 ? "," : "") +
                    fmt::format("{{\"unit\":{},\"verdict\":{},\"residual_over_floor\":{},\"needed\":{},\"disagreeing\":{}}}",
                                json::str(u.unit), json::str(u.verdict), json::num(u.ratio),
                                u.needed.empty() ? std::string("null") : json::str(u.needed), strings_json(u.disagreeing));
  }
  l.failed_json += "]";
  l.units_json += "]";
  return l;
}

}  // namespace

std::vector<ManifestRow> read_manifest(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::system_error(errno, std::generic_category(), "cannot open manifest " + path);
  const fs::path base = fs::path(path).parent_path();
  std::vector<ManifestRow> rows;
  std::string line;
  std::uint64_t n = 0;
  bool header = false;
  while (std::getline(in, line)) {
    ++n;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (trim(line).empty() || trim(line).front() == '#') continue;
    const auto comma = line.find(',');
    if (comma == std::string::npos || line.find(',', comma + 1) != std::string::npos) {
      throw InputError(Fault::kUsage, "a manifest row is \"unit,log\" (two fields): " + line, Where::at_file(path, n));
    }
    ManifestRow r{trim(line.substr(0, comma)), trim(line.substr(comma + 1)), n};
    if (!header) {
      if (r.unit != "unit" || r.log != "log") {
        throw InputError(Fault::kUsage, "the manifest's first line is the header \"unit,log\", not: " + line,
                         Where::at_file(path, n));
      }
      header = true;
      continue;
    }
    if (!safe_unit_name(r.unit) || r.log.empty()) {
      throw InputError(Fault::kUsage,
                       "unit '" + r.unit + "': a unit is a folder name of letters, digits, '_', '-', '.' (not first), "
                       "and every row names a log",
                       Where::at_file(path, n));
    }
    if (fs::path(r.log).is_relative()) r.log = (base / r.log).lexically_normal().string();
    rows.push_back(std::move(r));
  }
  if (!header) throw InputError(Fault::kUsage, "empty manifest: expected the header \"unit,log\"", Where::at_file(path));
  return rows;
}

std::string calibration_text(const CalibrationTable& table, const std::string& log, const std::string& format) {
  char date[32];
  const std::time_t now = std::time(nullptr);
  std::strftime(date, sizeof date, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&now));
  const TableOrigin origin{log, date, "resolver-model"};
  return format == "json"       ? format_table_json(table, origin)
         : format == "c-header" ? format_table_c_header(table, origin)
                                : format_table_csv(table, origin);
}

int run_fleet_units(const std::vector<ManifestRow>& rows, const std::string& manifest, const std::string& out_dir,
                    const FleetOptions& options) {
  std::map<std::string, std::vector<ManifestRow>> units;  // sorted by name: the same order every run
  for (const auto& r : rows) units[r.unit].push_back(r);
  int failed = 0;
  for (const auto& [unit, unit_rows] : units) {
    if (!options.merge_only) {
      for (const ManifestRow& r : unit_rows) (void)write_row_statistics(r, out_dir, options);
    }
    if (!merge_unit(unit, unit_rows, manifest, out_dir, options)) ++failed;
  }
  return failed;
}

std::string summarize_fleet(const std::string& out_dir, int& failed) {
  std::vector<UnitSummary> units = read_units(out_dir);
  const FleetPolePairs fleet = leave_out_other_p_r(units);
  const FleetTally t = tally_units(units);
  failed = static_cast<int>(units.size()) - t.done;
  const ParamSummary params = summarize_params(t.values);
  const FleetOutliers outliers = find_outliers(units, params, t.values);
  const UnitLists lists = list_units(units);
  write_text_file(out_dir + "/fleet.json",
                  fmt::format("{{\"units_total\":{},\"units_done\":{},\"units_failed\":{},\"logs_total\":{},"
                              "\"logs_left_out\":{},\"p_r\":{},\"params\":{},\"outliers\":{},\"proposed\":{},"
                              "\"needed\":{},\"failed\":{},\"units\":{}}}\n",
                              units.size(), t.done, failed, t.logs_total, t.logs_left_out, fleet.p_r, params.json,
                              outliers.json, effect_counts_json(t.proposed, t.done),
                              effect_counts_json(t.needed, t.done), lists.failed_json, lists.units_json));
  std::string text = fmt::format("fleet: {} units, {} done, {} failed ({} of {} logs left out); p_r = {}\n",
                                 units.size(), t.done, failed, t.logs_left_out, t.logs_total, fleet.p_r);
  text += params.table + outliers.lines;
  for (const auto& [e, n] : t.needed) text += fmt::format("needed: {} by {} of {} units\n", e, n, t.done);
  text += lists.failed_lines;
  write_fleet_page(out_dir);
  text += "wrote " + out_dir + "/fleet.json\nwrote " + out_dir + "/fleet.html\n";
  return text;
}

}  // namespace resolver
