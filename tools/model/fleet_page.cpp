#include "tools/model/fleet_page.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <set>
#include <sstream>
#include <system_error>
#include <vector>

#include "daemon/service/program_version.h"
#include "tools/model/html_page.h"
#include "tools/model/html_report.h"
#include "tools/model/report_assets.h"
#include "tools/model/report_data.h"

namespace resolver {

namespace fs = std::filesystem;

namespace {

using html::escape;
using html::num_cell;
using html::table;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
/// fleet.cpp's rule (find_outliers): outside the spread is |value - median| > 4 robust spreads,
/// judged only where the spread is > 0 over at least 3 units.
constexpr double kOutlierZ = 4.0;
constexpr long long kOutlierMinUnits = 3;
/// Units named per effect in the effects table before "and k more".
constexpr std::size_t kNamesShown = 24;
/// [% of its cell] the effects table's bar for every unit (room left for the number).
constexpr double kBarWidth = 75.0;
constexpr const char* kFleetColor = "#1f5fa8";
constexpr const char* kUnitColor = "#222222";
constexpr const char* kOutlierColor = "#c0392b";
constexpr const char* kThresholdColor = "#888888";

double number_or_nan(const json::Json& j) { return j.is_null() ? kNaN : j.number(); }
std::string g5(double v) { return std::isfinite(v) ? fmt::format("{:.5g}", v) : std::string("–"); }
std::string ratio_text(double v) { return std::isfinite(v) ? fmt::format("{:.2f}x", v) : std::string("–"); }

std::vector<std::string> texts(const json::Json& array) {
  std::vector<std::string> o;
  for (const auto& e : array.items) o.push_back(e.text);
  return o;
}

struct Param {
  std::string name;
  double value = kNaN, error = kNaN;
  std::string unit;
};

/// One unit as the page shows it: fleet.json's line, its unit.json's details.
struct UnitRow {
  std::string id;
  bool done = false;      ///< counted in the fleet's statistics
  bool has_file = false;  ///< DIR/UNIT/unit.json was read
  std::string verdict, reason, needed, model;
  double ratio = kNaN;
  int p = 0;
  long long logs = 0;
  std::vector<std::string> proposed, disagreeing, files, outside;  ///< outside: the parameters it is an outlier on
  std::map<std::string, double> z;                                  ///< robust z per such parameter (fleet.json's)
  std::vector<Param> params;
};

std::string unit_link(const std::string& id) {
  return fmt::format("<a href=\"#unit-{0}\">{0}</a>", escape(id));
}

/// Every unit fleet.json names, done and failed, in the order of their ids.
std::vector<UnitRow> unit_rows(const FleetPageInput& in) {
  std::map<std::string, UnitRow> rows;
  for (const auto& u : in.fleet["units"].items) {
    UnitRow& r = rows[u["unit"].text];
    r.id = u["unit"].text;
    r.done = true;
    r.verdict = u["verdict"].text;
    r.ratio = number_or_nan(u["residual_over_floor"]);
    r.needed = u["needed"].is_null() ? "" : u["needed"].text;
    r.disagreeing = texts(u["disagreeing"]);
  }
  for (const auto& f : in.fleet["failed"].items) {
    UnitRow& r = rows[f["unit"].text];
    r.id = f["unit"].text;
    r.reason = f["reason"].text;
  }
  for (const auto& o : in.fleet["outliers"].items) {
    if (const auto it = rows.find(o["unit"].text); it != rows.end()) {
      it->second.outside.push_back(o["param"].text);
      it->second.z[o["param"].text] = o["z"].number();
    }
  }
  for (auto& [id, r] : rows) {
    const auto it = in.units.find(id);
    if (it == in.units.end()) continue;
    r.has_file = true;
    const json::Json& j = it->second;
    try {
      if (j.has("log_rows")) r.logs = j["log_rows"].integer();
      if (j.has("files")) r.files = texts(j["files"]);
      if (!r.done || j["status"].text != "done") continue;
      r.p = static_cast<int>(j["p"].integer());
      r.model = fmt::format("{}", fmt::join(texts(j["effects"]), " + "));
      r.proposed = texts(j["proposed"]);
      for (const auto& [name, p] : j["params"].members) {
        r.params.push_back({name, p["value"].number(), number_or_nan(p["stderr"]), report::bare_unit(p["unit"].text)});
      }
    } catch (const std::exception&) {
      // Not as fleet writes it: the page shows what fleet.json says of the unit.
    }
  }
  std::vector<UnitRow> out;
  for (auto& [id, r] : rows) out.push_back(std::move(r));
  return out;
}

// ---- the header ------------------------------------------------------------------------

std::string header(const FleetPageInput& in, const std::vector<UnitRow>& units) {
  const json::Json& f = in.fleet;
  int explained = 0, missing = 0, unexplained = 0, failed = 0;
  std::set<int> p;
  std::set<std::string> models;
  for (const auto& u : units) {
    if (!u.done) {
      ++failed;
      continue;
    }
    if (u.verdict == "explained") ++explained;
    if (u.verdict == "missing_effect") ++missing;
    if (u.verdict == "unexplained") ++unexplained;
    if (u.p > 0) p.insert(u.p);
    if (!u.model.empty()) models.insert(u.model);
  }
  std::string o = fmt::format("<h1>Resolver fleet report: {}</h1>\n", escape(in.title));
  o += fmt::format(
      "<p class=\"meta\">{} units, {} logs · bench p<sub>r</sub> = {}, p = {} · model fitted: {} · written by "
      "<code>{}</code></p>\n",
      f["units_total"].integer(), f["logs_total"].integer(),
      f["p_r"].integer() > 0 ? std::to_string(f["p_r"].integer()) : std::string("–"),
      p.empty() ? std::string("–") : fmt::format("{}", fmt::join(p, " / ")),
      models.empty() ? std::string("–") : escape(fmt::format("{}", fmt::join(models, "; "))), escape(in.version));
  const char* tone = failed + unexplained > 0 ? "v-unexplained" : missing > 0 ? "v-missing_effect" : "v-explained";
  o += fmt::format(
      "<div class=\"verdict {}\"><b>{} units</b><div class=\"counts\"><span class=\"verdict-explained\">{} explained</span>"
      "<span class=\"verdict-missing_effect\">{} missing_effect</span><span class=\"verdict-unexplained\">{} "
      "unexplained</span><span class=\"verdict-failed\">{} failed</span></div>",
      tone, units.size(), explained, missing, unexplained, failed);
  std::vector<std::string> outside;
  for (const auto& u : units) {
    if (!u.outside.empty()) outside.push_back(fmt::format("{} ({})", unit_link(u.id), escape(fmt::format("{}", fmt::join(u.outside, ", ")))));
  }
  o += outside.empty() ? std::string("No unit is outside the fleet's spread.")
                       : fmt::format("{} unit{} outside the fleet's spread: {}.", outside.size(),
                                     outside.size() == 1 ? " is" : "s are", fmt::join(outside, "; "));
  if (failed > 0) {
    o += fmt::format("<p>Failed, and left out of the statistics ({} of {} logs):</p><ul class=\"failed-list\">",
                     f["logs_left_out"].integer(), f["logs_total"].integer());
    for (const auto& u : units) {
      if (!u.done) o += fmt::format("<li><b>{}</b>: {}</li>", unit_link(u.id), escape(u.reason));
    }
    o += "</ul>";
  }
  o += "</div>\n";
  o += "<nav class=\"small\">Contents: <a href=\"#params\">parameters</a> · <a href=\"#effects\">effects the units "
       "need</a> · <a href=\"#outliers\">units outside the spread</a> · <a href=\"#units\">every unit</a></nav>\n";
  return o;
}

// ---- the parameters ----------------------------------------------------------------------

/// A CSV column / element id from a parameter name ("quadrature.beta" -> "quadrature_beta").
std::string identifier(const std::string& name) {
  std::string o = name;
  std::replace_if(o.begin(), o.end(), [](unsigned char c) { return !std::isalnum(c) && c != '_'; }, '_');
  return o.empty() || std::isdigit(static_cast<unsigned char>(o.front())) ? "p_" + o : o;
}

std::string param_unit(const std::string& name, const std::vector<UnitRow>& units) {
  for (const auto& u : units) {
    for (const auto& p : u.params) {
      if (p.name == name) return p.unit;
    }
  }
  return "1";
}

bool judged(const json::Json& stat) {
  return stat["spread"].number() > 0.0 && stat["units"].integer() >= kOutlierMinUnits;
}

report::Series flat(std::string label, std::string color, double lo, double hi, double y) {
  report::Series s;
  s.label = std::move(label);
  s.color = std::move(color);
  s.x = {lo, hi};
  s.y = {y, y};
  return s;
}

/// The parameter's value per unit (x: the unit's row in the units table) over the fleet's
/// median, its robust spread band and the outlier threshold; the outliers in red, labelled.
report::Plot strip_plot(const std::string& name, const json::Json& stat, const std::vector<UnitRow>& units,
                        const std::string& unit) {
  report::Plot p;
  p.id = "param-" + identifier(name);
  p.group = "units";
  p.title = name + ": each unit's value, the fleet's median and spread";
  p.half = true;
  p.height = 260;
  p.x.label = "unit, by its row in the units table";
  p.x.unit = "row";
  p.x.column = "unit_row";
  p.x.lo = 0.5;
  p.x.hi = static_cast<double>(units.size()) + 0.5;
  p.x.step = 1.0;
  p.y.label = name;
  p.y.unit = unit;
  p.y.column = identifier(name);
  const double median = stat["median"].number(), spread = stat["spread"].number();
  const double n = static_cast<double>(stat["units"].integer());

  report::Series band = flat("robust spread: median ± 1.4826 MAD", kFleetColor, p.x.lo, p.x.hi, median);
  band.mark = report::Mark::kBand;
  band.spread = {spread, spread};
  band.count = {n, n};
  band.width = 0.0;
  p.series.push_back(std::move(band));
  p.series.push_back(flat("median", kFleetColor, p.x.lo, p.x.hi, median));
  if (judged(stat)) {
    report::Series hi = flat(fmt::format("outlier threshold: median ± {:g} spreads", kOutlierZ), kThresholdColor,
                             p.x.lo, p.x.hi, median + kOutlierZ * spread);
    hi.dashed = true;
    hi.width = 1.0;
    report::Series lo = hi;
    lo.y = {median - kOutlierZ * spread, median - kOutlierZ * spread};
    lo.legend = false;
    p.series.push_back(std::move(hi));
    p.series.push_back(std::move(lo));
  }
  report::Series all;
  all.label = "units (bar: ± standard error)";
  all.color = kUnitColor;
  all.mark = report::Mark::kPoints;
  all.width = 5.0;
  report::Series out = all;
  out.label = fmt::format("outside the spread (|robust z| > {:g})", kOutlierZ);
  out.color = kOutlierColor;
  out.width = 9.0;
  out.label_points = true;
  std::vector<std::string> named;
  for (std::size_t i = 0; i < units.size(); ++i) {
    const UnitRow& u = units[i];
    if (!u.done) continue;
    for (const auto& q : u.params) {
      if (q.name != name) continue;
      const double x = static_cast<double>(i + 1);
      all.x.push_back(x);
      all.y.push_back(q.value);
      all.error.push_back(q.error);
      all.names.push_back(u.id);
      if (std::find(u.outside.begin(), u.outside.end(), name) != u.outside.end()) {
        out.x.push_back(x);
        out.y.push_back(q.value);
        out.names.push_back(u.id);
        named.push_back(fmt::format("{} (z {:+.1f})", u.id, u.z.at(name)));
      }
    }
  }
  const bool any_outlier = !out.x.empty();
  const std::string unit_suffix = unit == "1" ? std::string() : " " + unit;
  p.series.push_back(std::move(all));
  if (any_outlier) p.series.push_back(std::move(out));
  p.caption = fmt::format(
      "{} units; median {}{}, robust spread {}{}. {} Error bars: each unit's standard error. Drag across some "
      "units to zoom in (the value axis then fits the units shown, so the rest can be compared beside a far "
      "outlier); the readout names the unit under the pointer; the plots zoom together.",
      stat["units"].integer(), g5(median), unit_suffix, g5(spread), unit_suffix,
      !judged(stat)     ? "The spread is 0 or the units too few: no unit is judged an outlier on it."
      : named.empty() ? "No unit outside the spread."
                      : fmt::format("Outside the spread: {}.", fmt::join(named, ", ")));
  return p;
}

std::string params_section(const FleetPageInput& in, const std::vector<UnitRow>& units, std::vector<report::Plot>& plots) {
  std::string o = "<h2 id=\"params\">Parameters over the fleet</h2>\n";
  const json::Json& params = in.fleet["params"];
  if (params.members.empty()) return o + "<p>No unit was fitted: no parameter to show.</p>\n";
  std::vector<std::vector<std::string>> rows;
  for (const auto& [name, s] : params.members) {
    const std::string unit = param_unit(name, units);
    const auto outliers = std::count_if(units.begin(), units.end(), [&param = name](const UnitRow& u) {
      return u.z.contains(param);
    });
    rows.push_back({"<a href=\"#fig-param-" + escape(identifier(name)) + "\"><code>" + escape(name) + "</code></a>",
                    escape(unit), num_cell(std::to_string(s["units"].integer())),
                    num_cell("<b>" + g5(s["median"].number()) + "</b>"), num_cell(g5(s["spread"].number())),
                    num_cell(g5(s["q05"].number())), num_cell(g5(s["q25"].number())), num_cell(g5(s["q75"].number())),
                    num_cell(g5(s["q95"].number())), num_cell(g5(s["min"].number())), num_cell(g5(s["max"].number())),
                    num_cell(std::to_string(outliers))});
    plots.push_back(strip_plot(name, s, units, unit));
  }
  o += table("params",
             {"parameter", "unit", "units", "median", "robust spread (1.4826 MAD)", "q05", "q25", "q75", "q95", "min",
              "max", "units outside"},
             rows);
  o += fmt::format(
      "<p class=\"small\">Over the units done. Quantiles interpolate between order statistics. A unit is outside "
      "the spread when its robust z = (value − median) / spread exceeds ±{:g} (judged where the spread is > 0 over "
      "at least {} units).</p>\n",
      kOutlierZ, kOutlierMinUnits);
  o += "<p class=\"small\">Drag across a plot to zoom into some units, turn the mouse wheel to zoom about the pointer, "
       "shift-drag to pan, double-click (or <i>reset zoom</i>) to see them all. Click a legend entry to show or hide "
       "it. <i>download CSV</i> saves the plot's points (x: the unit's row in the units table).</p>\n"
       "<noscript><p class=\"bad\">The plots are drawn by the page's script: enable JavaScript to see them. The "
       "tables do not need it.</p></noscript>\n";
  return o + html::figures(plots);
}

// ---- effects, outliers, units ------------------------------------------------------------

std::string effects_section(const FleetPageInput& in, const std::vector<UnitRow>& units) {
  struct Effect {
    std::string name;
    long long proposed = 0, needed = 0;
    std::vector<std::string> by;
  };
  std::map<std::string, Effect> m;
  for (const auto& e : in.fleet["proposed"].items) m[e["effect"].text].proposed = e["units"].integer();
  for (const auto& e : in.fleet["needed"].items) m[e["effect"].text].needed = e["units"].integer();
  const long long done = in.fleet["units_done"].integer();
  std::vector<Effect> effects;
  for (auto& [name, e] : m) {
    e.name = name;
    for (const auto& u : units) {
      if (u.done && std::find(u.proposed.begin(), u.proposed.end(), name) != u.proposed.end()) e.by.push_back(u.id);
    }
    effects.push_back(std::move(e));
  }
  std::stable_sort(effects.begin(), effects.end(), [](const Effect& a, const Effect& b) {
    return a.proposed != b.proposed ? a.proposed > b.proposed : a.needed > b.needed;
  });
  std::string o = "<h2 id=\"effects\">Effects the units need</h2>\n";
  if (effects.empty()) {
    return o + "<p>No unit's discovery proposed an effect beyond the model fitted: the fleet needs nothing more.</p>\n";
  }
  std::vector<std::vector<std::string>> rows;
  for (const auto& e : effects) {
    const double share = done > 0 ? static_cast<double>(e.proposed) / static_cast<double>(done) : 0.0;
    std::vector<std::string> shown;
    for (std::size_t i = 0; i < e.by.size() && i < kNamesShown; ++i) shown.push_back(unit_link(e.by[i]));
    std::string names = fmt::format("{}", fmt::join(shown, ", "));
    if (e.by.size() > kNamesShown) names += fmt::format(" and {} more", e.by.size() - kNamesShown);
    rows.push_back({"<code>" + escape(e.name) + "</code>", num_cell(fmt::format("{} of {}", e.proposed, done)),
                    fmt::format("<td class=\"barcell\"><span class=\"bar\" style=\"width:{:.1f}%\"></span> {:.0f} %</td>",
                                kBarWidth * share, 100.0 * share),
                    num_cell(std::to_string(e.needed)), 2 * e.proposed > done ? "<b>yes</b>" : "no",
                    "<td class=\"units\">" + names + "</td>"});
  }
  return o + table("params",
                   {"effect", "units whose discovery proposed it", "share of the units done",
                    "units whose missing effect it is", "most units", "which units"},
                   rows) +
         "<p class=\"small\">Proposed: the explain of a unit's calibration log ranks the effect as one to add. "
         "Missing effect: the unit's verdict is missing_effect and this is its best candidate. Add an effect most units "
         "need to the fleet's model (<code>--effects</code>) and run the fleet again.</p>\n";
}

std::string outliers_section(const FleetPageInput& in, const std::vector<UnitRow>& units) {
  std::string o = "<h2 id=\"outliers\">Units outside the spread</h2>\n";
  std::vector<const json::Json*> list;
  for (const auto& x : in.fleet["outliers"].items) list.push_back(&x);
  if (list.empty()) return o + "<p>None: every unit's parameters are within the fleet's spread.</p>\n";
  std::stable_sort(list.begin(), list.end(), [](const json::Json* a, const json::Json* b) {
    return std::abs((*a)["z"].number()) > std::abs((*b)["z"].number());
  });
  std::vector<std::vector<std::string>> rows;
  for (const json::Json* x : list) {
    const std::string& name = (*x)["param"].text;
    const json::Json& s = in.fleet["params"][name];
    rows.push_back({unit_link((*x)["unit"].text), "<code>" + escape(name) + "</code>",
                    num_cell("<b>" + g5((*x)["value"].number()) + "</b>"), escape(param_unit(name, units)),
                    num_cell(g5(s["median"].number())), num_cell(g5(s["spread"].number())),
                    num_cell(fmt::format("{:+.1f}", (*x)["z"].number()))});
  }
  return o + table("params outliers", {"unit", "parameter", "value", "unit of the value", "fleet median", "robust spread", "robust z"},
                   rows) +
         "<p class=\"small\">Largest |robust z| first.</p>\n";
}

std::string units_section(const std::vector<UnitRow>& units) {
  std::vector<std::vector<std::string>> rows;
  for (std::size_t i = 0; i < units.size(); ++i) {
    const UnitRow& u = units[i];
    std::vector<std::string> links;
    const std::string dir = escape(u.id);
    if (u.has_file) links.push_back(fmt::format("<a href=\"{0}/unit.json\">unit.json</a>", dir));
    for (const auto& f : u.files) links.push_back(fmt::format("<a href=\"{0}/{1}\">{1}</a>", dir, escape(f)));
    std::string notes;
    if (!u.done) {
      notes = escape(u.reason);
    } else if (!u.disagreeing.empty()) {
      notes = "its logs disagree on " + escape(fmt::format("{}", fmt::join(u.disagreeing, ", ")));
    }
    rows.push_back({num_cell(std::to_string(i + 1)),
                    fmt::format("<td id=\"unit-{0}\"><b>{0}</b></td>", escape(u.id)),
                    u.done ? fmt::format("<td class=\"verdict-{0}\">{0}</td>", escape(u.verdict))
                           : std::string("<td class=\"verdict-failed\">failed</td>"),
                    u.done ? fmt::format("<td class=\"num {}\">{}</td>", u.verdict == "explained" ? "ok" : "bad",
                                         ratio_text(u.ratio))
                           : std::string("<td class=\"na\">–</td>"),
                    escape(u.needed), "<td class=\"units\">" + escape(fmt::format("{}", fmt::join(u.proposed, ", "))) + "</td>",
                    escape(fmt::format("{}", fmt::join(u.outside, ", "))), num_cell(std::to_string(u.logs)),
                    "<td class=\"why\">" + notes + "</td>", fmt::format("{}", fmt::join(links, " · "))});
  }
  return "<h2 id=\"units\">Every unit</h2>\n" +
         table("params units",
               {"row", "unit", "verdict", "residual / floor", "missing effect", "proposed", "outside the spread on",
                "logs", "notes", "its files"},
               rows) +
         "<p class=\"small\">Residual / floor: the position-error residual of the unit's calibration log (the one with "
         "the smallest) against its noise floor. The files are the unit's folder beside this page: its unit.json "
         "(every log's fit) and its calibration in <code>resolver-model export</code>'s formats.</p>\n";
}

std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::system_error(errno, std::generic_category(), "cannot read " + path.string());
  std::stringstream text;
  text << in.rdbuf();
  std::string s = text.str();
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.pop_back();
  return s;
}

}  // namespace

std::string format_fleet_html(const FleetPageInput& in) {
  const std::vector<UnitRow> units = unit_rows(in);
  std::vector<report::Plot> plots;
  std::string o = html::page_head("resolver-model fleet: " + in.title, report_assets::fleet_page_css());
  o += header(in, units);
  o += params_section(in, units, plots);
  o += effects_section(in, units);
  o += outliers_section(in, units);
  o += units_section(units);
  o += fmt::format(
      "<p class=\"small\">Written by <code>resolver-model fleet</code> ({}) from the fleet's <code>fleet.json</code> "
      "and its units' <code>unit.json</code>. Plots drawn with uPlot {} (MIT licence, embedded in this page with its "
      "notice).</p>\n",
      escape(in.version), escape(report_assets::uplot_version()));
  return o + html::page_tail(plots, report_assets::fleet_page_js(), "fleet_page.js");
}

void write_fleet_page(const std::string& out_dir) {
  FleetPageInput in;
  fs::path dir = fs::absolute(out_dir).lexically_normal();
  if (!dir.has_filename()) dir = dir.parent_path();
  in.title = dir.filename().string();
  in.fleet = json::parse_json(read_text(fs::path(out_dir) / "fleet.json"));
  for (const char* list : {"units", "failed"}) {
    for (const auto& u : in.fleet[list].items) {
      const fs::path file = fs::path(out_dir) / u["unit"].text / "unit.json";
      try {
        in.units[u["unit"].text] = json::parse_json(read_text(file));
      } catch (const std::exception&) {
        // None, or unreadable: the page shows what fleet.json says of the unit.
      }
    }
  }
  in.version = version_line("resolver-model");
  write_text_file(out_dir + "/fleet.html", format_fleet_html(in));
}

}  // namespace resolver
