#include "tools/model/stats_file.h"

#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>

#include <fmt/format.h>

#include "daemon/core/errors.h"
#include "tools/model/json_text.h"
#include "tools/model/json_value.h"

namespace resolver {

namespace {

constexpr const char* kFormat = "resolver-model stats";
/// Every double written so that it reads back bit for bit.
constexpr int kExact = 17;
constexpr const char* kGroupNames[kGroups] = {"rd", "sc", "cur"};

std::string num(double v) { return json::num(v, kExact); }

std::string strings(const std::vector<std::string>& v) {
  std::string o = "[";
  for (std::size_t i = 0; i < v.size(); ++i) o += (i > 0 ? "," : "") + json::str(v[i]);
  return o + "]";
}

std::string vector_of(const Eigen::VectorXd& v) {
  return json::array(std::vector<double>(v.data(), v.data() + v.size()), kExact);
}

std::string normal_equations(const NormalEquations& ne) {
  std::string m = "[";
  for (Eigen::Index i = 0; i < ne.m().rows(); ++i) {
    // The matrix is symmetric: its upper triangle, row by row.
    std::vector<double> row;
    for (Eigen::Index j = i; j < ne.m().cols(); ++j) row.push_back(ne.m()(i, j));
    m += (i > 0 ? "," : "") + json::array(row, kExact);
  }
  m += "]";
  return fmt::format("{{\"n\":{},\"yy\":{},\"b\":{},\"m_upper\":{}}}", ne.n(), num(ne.yy()), vector_of(ne.b()), m);
}

std::string motion_of(const MotionSummary& m) {
  return fmt::format(
      "{{\"samples\":{},\"moving\":{},\"standstill\":{},\"forward\":{},\"backward\":{},\"reversals\":{},"
      "\"standstills\":{},\"travelled\":{},\"span_s\":{},\"omega_min\":{},\"omega_max\":{},\"angle_noise\":{}}}",
      m.samples, m.moving, m.standstill, m.forward, m.backward, m.reversals, m.standstills, num(m.travelled),
      num(m.span_s), num(m.omega_min), num(m.omega_max), num(m.angle_noise));
}

std::string params_of(const std::vector<ModelParameter>& ps) {
  std::string o = "[";
  for (std::size_t i = 0; i < ps.size(); ++i) {
    o += fmt::format("{}{{\"name\":{},\"value\":{},\"std_error\":{},\"unit\":{}}}", i > 0 ? "," : "",
                     json::str(ps[i].name), num(ps[i].value), num(ps[i].std_error), json::str(ps[i].unit));
  }
  return o + "]";
}

std::string floor_estimate(const FloorEstimate& f) {
  return fmt::format(
      "{{\"chosen\":{},\"second_difference\":{},\"standstill\":{},\"quantization\":{},\"standstill_samples\":{},"
      "\"source\":{}}}",
      num(f.chosen), num(f.second_difference), num(f.standstill), num(f.quantization), f.standstill_samples,
      json::str(f.source));
}

/// Reads members of the parsed file; any fault is an InputError naming the file.
class Reader {
 public:
  Reader(const json::Json& root, std::string path) : root_(root), path_(std::move(path)) {}

  [[noreturn]] void fail(const std::string& what) const {
    throw InputError(Fault::kUsage, what, Where::at_file(path_));
  }
  const json::Json& at(const json::Json& j, std::string_view key) const {
    if (j.kind != json::Json::Kind::kObject || !j.has(key)) fail(fmt::format("not a statistics file: no member \"{}\"", key));
    return j[key];
  }
  double number(const json::Json& j) const {
    if (j.is_null()) return std::numeric_limits<double>::quiet_NaN();
    if (j.kind != json::Json::Kind::kNumber) fail("not a statistics file: a number expected");
    return j.number();
  }
  double number(const json::Json& j, std::string_view key) const { return number(at(j, key)); }
  long long integer(const json::Json& j, std::string_view key) const {
    const json::Json& v = at(j, key);
    if (v.kind != json::Json::Kind::kNumber) fail(fmt::format("not a statistics file: \"{}\" is not a number", key));
    return v.integer();
  }
  bool boolean(const json::Json& j, std::string_view key) const {
    const json::Json& v = at(j, key);
    if (v.kind != json::Json::Kind::kBool) fail(fmt::format("not a statistics file: \"{}\" is not true or false", key));
    return v.boolean;
  }
  std::string text(const json::Json& j, std::string_view key) const {
    const json::Json& v = at(j, key);
    if (v.kind != json::Json::Kind::kString) fail(fmt::format("not a statistics file: \"{}\" is not a string", key));
    return v.text;
  }
  const std::vector<json::Json>& items(const json::Json& j, std::string_view key) const {
    const json::Json& v = at(j, key);
    if (v.kind != json::Json::Kind::kArray) fail(fmt::format("not a statistics file: \"{}\" is not an array", key));
    return v.items;
  }
  std::vector<std::string> strings(const json::Json& j, std::string_view key) const {
    std::vector<std::string> out;
    for (const json::Json& v : items(j, key)) {
      if (v.kind != json::Json::Kind::kString) fail(fmt::format("not a statistics file: \"{}\" holds a non-string", key));
      out.push_back(v.text);
    }
    return out;
  }
  std::vector<double> numbers(const std::vector<json::Json>& v) const {
    std::vector<double> out;
    out.reserve(v.size());
    for (const json::Json& x : v) out.push_back(number(x));
    return out;
  }
  Eigen::VectorXd vector(const json::Json& j, std::string_view key, std::size_t size) const {
    const std::vector<double> v = numbers(items(j, key));
    if (v.size() != size) fail(fmt::format("\"{}\" has {} entries for {} columns", key, v.size(), size));
    return Eigen::Map<const Eigen::VectorXd>(v.data(), static_cast<Eigen::Index>(v.size()));
  }
  NormalEquations normal_equations(const json::Json& j, std::size_t k) const {
    const auto n = static_cast<Eigen::Index>(k);
    Eigen::MatrixXd m(n, n);
    const std::vector<json::Json>& rows = items(j, "m_upper");
    if (rows.size() != k) fail(fmt::format("a matrix has {} rows for {} columns", rows.size(), k));
    for (Eigen::Index i = 0; i < n; ++i) {
      const std::vector<double> row = numbers(rows[static_cast<std::size_t>(i)].items);
      if (row.size() != k - static_cast<std::size_t>(i)) fail("a matrix row has the wrong length");
      for (Eigen::Index c = i; c < n; ++c) m(i, c) = m(c, i) = row[static_cast<std::size_t>(c - i)];
    }
    NormalEquations out;
    out.set(std::move(m), vector(j, "b", k), number(j, "yy"), integer(j, "n"));
    return out;
  }
  FloorEstimate floor_estimate(const json::Json& j) const {
    FloorEstimate f;
    f.chosen = number(j, "chosen");
    f.second_difference = number(j, "second_difference");
    f.standstill = number(j, "standstill");
    f.quantization = number(j, "quantization");
    f.standstill_samples = integer(j, "standstill_samples");
    f.source = text(j, "source");
    return f;
  }
  MotionSummary motion(const json::Json& j) const {
    MotionSummary m;
    m.samples = integer(j, "samples");
    m.moving = integer(j, "moving");
    m.standstill = integer(j, "standstill");
    m.forward = integer(j, "forward");
    m.backward = integer(j, "backward");
    m.reversals = static_cast<int>(integer(j, "reversals"));
    m.standstills = static_cast<int>(integer(j, "standstills"));
    m.travelled = number(j, "travelled");
    m.span_s = number(j, "span_s");
    m.omega_min = number(j, "omega_min");
    m.omega_max = number(j, "omega_max");
    m.angle_noise = number(j, "angle_noise");
    return m;
  }
  const json::Json& root() const { return root_; }

 private:
  const json::Json& root_;
  std::string path_;
};

void read_run(const Reader& r, const json::Json& root, RunStatistics& run) {
  PoolLayout& l = run.layout;
  l.p_r = static_cast<int>(r.integer(r.at(root, "bench"), "p_r"));
  l.p = static_cast<int>(r.integer(r.at(root, "bench"), "p"));
  const json::Json& sig = r.at(root, "signals");
  l.reference = r.boolean(sig, "reference");
  l.reference_aligned = r.boolean(sig, "reference_aligned");
  l.rd = r.boolean(sig, "rd");
  l.sincos = r.boolean(sig, "sincos");
  l.currents = r.boolean(sig, "currents");
  run.effects = r.strings(root, "effects");
  for (const json::Json& p : r.items(root, "params")) {
    run.params.push_back({r.text(p, "name"), r.number(p, "value"), r.number(p, "std_error"), r.text(p, "unit")});
  }
  for (const json::Json& v : r.items(root, "values")) run.values.push_back(r.numbers(v.items));
  run.frame_shift = r.number(root, "frame_shift");
  run.columns = r.strings(root, "columns");
  run.candidate_sets = r.strings(root, "candidate_sets");
  run.nuisance_columns = static_cast<int>(r.integer(root, "nuisance_columns"));
  run.model_columns = static_cast<int>(r.integer(root, "model_columns"));
  const std::size_t k = run.columns.size();
  run.point = r.vector(root, "point", k);
  const json::Json& floors = r.at(root, "floors");
  run.floors = {r.floor_estimate(r.at(floors, "rd")), r.floor_estimate(r.at(floors, "sc")),
                r.floor_estimate(r.at(floors, "cur"))};
  const json::Json& counts = r.at(root, "counts");
  run.fitted_rows = r.integer(counts, "fitted_rows");
  run.samples = r.integer(counts, "samples");
  run.span_s = r.number(counts, "span_s");
  run.electrical_revolutions = r.number(counts, "electrical_revolutions");
  run.motion = r.motion(r.at(root, "motion"));
  run.notes = r.strings(root, "notes");
  run.untrusted = r.strings(root, "untrusted");
  const json::Json& outliers = r.at(root, "outliers");
  run.outlier_samples = r.integer(outliers, "samples");
  const Eigen::VectorXd rss = r.vector(outliers, "rss", kGroups);
  const Eigen::VectorXd rows = r.vector(outliers, "rows", kGroups);
  for (std::size_t g = 0; g < static_cast<std::size_t>(kGroups); ++g) {
    run.outlier_rss[g] = rss[static_cast<Eigen::Index>(g)];
    run.outlier_rows[g] = static_cast<std::int64_t>(std::llround(rows[static_cast<Eigen::Index>(g)]));
  }
  run.stats = PassStatistics(static_cast<int>(k));
  const json::Json& groups = r.at(root, "groups");
  for (std::size_t g = 0; g < static_cast<std::size_t>(kGroups); ++g) {
    const json::Json& one = r.at(groups, kGroupNames[g]);
    run.stats.all[g] = r.normal_equations(r.at(one, "all"), k);
    run.stats.fold_a[g] = r.normal_equations(r.at(one, "fold_a"), k);
  }
}

/// One run's object of the file.
std::string format_run(const std::string& name, const RunStatistics& run) {
  std::string values = "[";
  for (std::size_t i = 0; i < run.values.size(); ++i) values += (i > 0 ? "," : "") + json::array(run.values[i], kExact);
  values += "]";
  std::string groups = "{";
  for (std::size_t g = 0; g < static_cast<std::size_t>(kGroups); ++g) {
    groups += fmt::format("{}\"{}\":{{\"all\":{},\"fold_a\":{}}}", g > 0 ? ",\n  " : "\n  ", kGroupNames[g],
                          normal_equations(run.stats.all[g]), normal_equations(run.stats.fold_a[g]));
  }
  groups += "}";
  return fmt::format(
      "{{\"name\":{},\"bench\":{{\"p_r\":{},\"p\":{}}},\n"
      "\"signals\":{{\"reference\":{},\"reference_aligned\":{},\"rd\":{},\"sincos\":{},\"currents\":{}}},\n"
      "\"effects\":{},\"params\":{},\n\"values\":{},\"frame_shift\":{},\n"
      "\"columns\":{},\"candidate_sets\":{},\"nuisance_columns\":{},\"model_columns\":{},\n\"point\":{},\n"
      "\"floors\":{{\"rd\":{},\"sc\":{},\"cur\":{}}},\n"
      "\"counts\":{{\"fitted_rows\":{},\"samples\":{},\"span_s\":{},\"electrical_revolutions\":{}}},\n"
      "\"motion\":{},\n\"notes\":{},\"untrusted\":{},\n"
      "\"outliers\":{{\"samples\":{},\"rows\":{},\"rss\":{}}},\n\"groups\":{}}}",
      json::str(name), run.layout.p_r, run.layout.p, run.layout.reference, run.layout.reference_aligned,
      run.layout.rd, run.layout.sincos, run.layout.currents, strings(run.effects), params_of(run.params), values, num(run.frame_shift), strings(run.columns), strings(run.candidate_sets), run.nuisance_columns,
      run.model_columns, vector_of(run.point), floor_estimate(run.floors.rd), floor_estimate(run.floors.sc),
      floor_estimate(run.floors.cur), run.fitted_rows, run.samples, num(run.span_s), num(run.electrical_revolutions),
      motion_of(run.motion), strings(run.notes), strings(run.untrusted), run.outlier_samples,
      json::array(std::vector<double>(run.outlier_rows.begin(), run.outlier_rows.end()), kExact),
      json::array(run.outlier_rss, kExact), groups);
}

}  // namespace

std::string format_stats_file(const StatsFile& file) {
  std::string runs;
  for (std::size_t i = 0; i < file.runs.size(); ++i) {
    runs += (i > 0 ? ",\n" : "\n") + format_run(file.runs[i].name, file.runs[i].run);
  }
  return fmt::format("{{\"format\":{},\"version\":{},\"tool\":{},\"log\":{},\n"
                     "\"layout\":{{\"id\":{},\"description\":{}}},\n\"left_out\":{},\n\"input\":{},\n\"runs\":[{}]}}\n",
                     json::str(kFormat), kStatsFileVersion, json::str(file.tool), json::str(file.log),
                     json::str(file.layout_id), json::str(file.layout_description), strings(file.left_out),
                     strings(file.input), runs);
}

StatsFile parse_stats_file(const std::string& text, const std::string& path) {
  json::Json root;
  try {
    root = json::parse_json(text);
  } catch (const std::exception& e) {
    throw InputError(Fault::kUsage, std::string("not a statistics file (resolver-model stats writes them): ") + e.what(),
                     Where::at_file(path));
  }
  const Reader r(root, path);
  if (root.kind != json::Json::Kind::kObject || !root.has("format") || root["format"].text != kFormat) {
    r.fail("not a statistics file (resolver-model stats writes them): no \"format\": \"resolver-model stats\"");
  }
  const long long version = r.integer(root, "version");
  StatsFile out;
  out.tool = r.text(root, "tool");
  if (version != kStatsFileVersion) {
    r.fail(fmt::format("statistics file version {} (written by {}); this resolver-model reads version {}: make it "
                       "again with this resolver-model stats",
                       version, out.tool, kStatsFileVersion));
  }
  out.log = r.text(root, "log");
  out.layout_id = r.text(r.at(root, "layout"), "id");
  out.layout_description = r.text(r.at(root, "layout"), "description");
  out.left_out = r.strings(root, "left_out");
  out.input = r.strings(root, "input");
  for (const json::Json& j : r.items(root, "runs")) {
    NamedRun run;
    run.name = r.text(j, "name");
    read_run(r, j, run.run);
    out.runs.push_back(std::move(run));
  }
  if (out.runs.empty()) r.fail("the statistics file holds no run");
  return out;
}

StatsFile read_stats_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IoError(fmt::format("cannot open: {}", std::strerror(errno)), Where::at_file(path));
  std::ostringstream text;
  text << in.rdbuf();
  return parse_stats_file(text.str(), path);
}

void check_same_layout(const std::vector<StatsFile>& files, const std::vector<std::string>& paths) {
  for (std::size_t i = 1; i < files.size(); ++i) {
    if (files[i].layout_id == files.front().layout_id) continue;
    throw InputError(Fault::kUsage,
                     fmt::format("made with another layout ({}) than {} ({}): merge statistics of one layout",
                                 files[i].layout_description, paths.front(), files.front().layout_description),
                     Where::at_file(paths[i]));
  }
}

}  // namespace resolver
