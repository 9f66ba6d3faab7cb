#include "daemon/service/table_file.h"

#include <charconv>
#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "daemon/core/angles.h"
#include "drivers/text/json_string.h"

namespace resolver {

namespace {

constexpr const char* kMagic = "# resolver-bench calibration table, format 1";

std::string json_str(std::string_view s) { return text::json_string(s); }

std::string header_lines(const CalibrationTable& t, const TableOrigin& o, const char* c) {
  std::string h;
  h += fmt::format("{} model: {}\n", c, fmt::join(t.model, ", "));
  h += fmt::format("{} p_r: {}\n{} p: {}\n", c, t.p_r, c, t.p);
  h += fmt::format("{} points: {}\n", c, t.correction.size());
  h += fmt::format("{} indexing: correction at the measured mechanical angle 2 pi index / points (the resolver angle "
                   "unwrapped / p_r + the cycle offset; p_r = 1: the resolver angle)\n",
                   c);
  h += fmt::format("{} interpolation: linear, periodic; max error {:.3g} rad (on a 16x finer grid)\n", c,
                   t.interpolation_error);
  h += fmt::format("{} use: theta_c = theta_meas + correction + omega * delay_s + p_r * backlash_rad / 2 * "
                   "sign(omega)  [rad, resolver electrical; omega resolver electrical rad/s]\n",
                   c);
  h += fmt::format("{} delay_s: {}\n{} backlash_rad: {}\n", c, t.delay, c, t.backlash);
  h += fmt::format("{} date: {}\n{} log: {}\n{} tool: {}\n", c, o.date, c, o.log, c, o.tool);
  for (const ModelParameter& p : t.parameters) {
    h += fmt::format("{} param: {} {} +- {} {}\n", c, p.name, p.value, p.std_error, p.unit);
  }
  return h;
}

double number(std::string_view text, const std::string& where) {
  double v = 0.0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
  if (ec != std::errc{} || end != text.data() + text.size() || !std::isfinite(v)) {
    throw std::runtime_error(where + ": '" + std::string(text) + "' is not a number");
  }
  return v;
}

}  // namespace

std::string c_float_literal(double value, bool single) {
  const double limit = single ? static_cast<double>(std::numeric_limits<float>::max())
                              : std::numeric_limits<double>::max();
  if (!(std::abs(value) <= limit)) {  // NaN too
    throw std::invalid_argument(fmt::format("{} has no C {} literal (a table entry must be finite and within "
                                            "the type's range)",
                                            value, single ? "float" : "double"));
  }
  // Written as the float it becomes: a value below float's range is 0.0f, not a
  // literal the compiler warns about.
  const double v = single ? static_cast<double>(static_cast<float>(value)) : value;
  std::string text = single ? fmt::format("{:.9g}", v) : fmt::format("{}", v);
  // "%.9g" and fmt's shortest form drop the point of an integral value ("0", "-0", "100").
  if (text.find_first_of(".eE") == std::string::npos) text += ".0";
  return single ? text + "f" : text;
}

std::string format_table_csv(const CalibrationTable& t, const TableOrigin& o) {
  std::string out = std::string(kMagic) + "\n" + header_lines(t, o, "#");
  out += "index,theta_m_rad,correction_rad\n";
  const auto n = static_cast<double>(t.correction.size());
  for (std::size_t i = 0; i < t.correction.size(); ++i) {
    out += fmt::format("{},{},{}\n", i, kTwoPi * static_cast<double>(i) / n, t.correction[i]);
  }
  return out;
}

std::string format_table_json(const CalibrationTable& t, const TableOrigin& o) {
  std::string params;
  for (const ModelParameter& p : t.parameters) {
    params += fmt::format("{}{{\"name\":{},\"value\":{},\"stderr\":{},\"unit\":{}}}", params.empty() ? "" : ",",
                          json_str(p.name), p.value, std::isfinite(p.std_error) ? fmt::format("{}", p.std_error) : "null",
                          json_str(p.unit));
  }
  std::string model;
  for (const std::string& m : t.model) model += (model.empty() ? "" : ",") + json_str(m);
  return fmt::format(
      "{{\"format\":\"resolver-bench-calibration\",\"version\":1,\"model\":[{}],\"p_r\":{},\"p\":{},\"points\":{},"
      "\"indexing\":\"measured mechanical angle 2 pi index / points\",\"interpolation\":\"linear, periodic\","
      "\"interpolation_error_rad\":{},\"delay_s\":{},\"backlash_rad\":{},\"date\":{},\"log\":{},\"tool\":{},"
      "\"params\":[{}],\"fourier_theta_m\":{{\"a\":[{}],\"b\":[{}]}},\"correction_rad\":[{}]}}\n",
      model, t.p_r, t.p, t.correction.size(), t.interpolation_error, t.delay, t.backlash, json_str(o.date),
      json_str(o.log), json_str(o.tool), params, fmt::join(t.a, ","), fmt::join(t.b, ","),
      fmt::join(t.correction, ","));
}

std::string format_table_c_header(const CalibrationTable& t, const TableOrigin& o) {
  std::string out = "/* resolver-bench calibration table, format 1\n" + header_lines(t, o, " *") + " */\n";
  out += "#ifndef RESOLVER_CALIBRATION_TABLE_H\n#define RESOLVER_CALIBRATION_TABLE_H\n\n";
  out += fmt::format("#define RESOLVER_CAL_POINTS {}\n#define RESOLVER_CAL_P_R {}\n#define RESOLVER_CAL_P {}\n",
                     t.correction.size(), t.p_r, t.p);
  out += fmt::format("static const double resolver_cal_delay_s = {};\n", c_float_literal(t.delay, false));
  out += fmt::format("static const double resolver_cal_backlash_rad = {};\n", c_float_literal(t.backlash, false));
  out += "/* [rad, resolver electrical] at the measured mechanical angle 2 pi i / RESOLVER_CAL_POINTS */\n";
  out += "static const float resolver_cal_correction_rad[RESOLVER_CAL_POINTS] = {\n";
  for (std::size_t i = 0; i < t.correction.size(); ++i) {
    out += fmt::format("{}{},{}", i % 6 == 0 ? "  " : " ", c_float_literal(t.correction[i]), i % 6 == 5 ? "\n" : "");
  }
  out += "\n};\n\n#endif /* RESOLVER_CALIBRATION_TABLE_H */\n";
  return out;
}

CalibrationTable read_table_csv(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot open calibration table " + path);
  CalibrationTable t;
  std::string line;
  int n = 0;
  bool header = false, magic = false;
  std::size_t points = 0;
  while (std::getline(in, line)) {
    ++n;
    const std::string where = fmt::format("{}:{}", path, n);
    if (n == 1) {
      if (line != kMagic) throw std::runtime_error(where + ": not a calibration table (the first line must be '" + kMagic + "'; export one with resolver-model export --table-format csv)");
      magic = true;
      continue;
    }
    if (!line.empty() && line[0] == '#') {
      const std::size_t colon = line.find(':');
      if (colon == std::string::npos) continue;
      const std::string key = line.substr(2, colon - 2);
      const std::string value = line.substr(colon + 2);
      if (key == "p_r") t.p_r = static_cast<int>(number(value, where));
      else if (key == "p") t.p = static_cast<int>(number(value, where));
      else if (key == "points") points = static_cast<std::size_t>(number(value, where));
      else if (key == "delay_s") t.delay = number(value, where);
      else if (key == "backlash_rad") t.backlash = number(value, where);
      else if (key == "interpolation") {
        const std::size_t at = value.find("max error ");
        const std::size_t end = value.find(" rad", at);
        if (at != std::string::npos && end != std::string::npos) {
          t.interpolation_error = number(value.substr(at + 10, end - at - 10), where);
        }
      }
      continue;
    }
    if (!header) {
      if (line != "index,theta_m_rad,correction_rad") throw std::runtime_error(where + ": expected the column line 'index,theta_m_rad,correction_rad'");
      header = true;
      continue;
    }
    std::istringstream cells(line);
    std::string a, b, c;
    if (!std::getline(cells, a, ',') || !std::getline(cells, b, ',') || !std::getline(cells, c)) {
      throw std::runtime_error(where + ": expected three comma-separated values");
    }
    const double index = number(a, where);
    if (index != static_cast<double>(t.correction.size())) {
      throw std::runtime_error(where + ": index " + a + " out of order (expected " + std::to_string(t.correction.size()) + ")");
    }
    t.correction.push_back(number(c, where));
  }
  if (!magic) throw std::runtime_error(path + ": empty file, not a calibration table");
  if (t.p_r < 1 || t.p < 1) throw std::runtime_error(path + ": p_r and p must be >= 1");
  if (t.correction.size() < 8 || (points != 0 && points != t.correction.size())) {
    throw std::runtime_error(fmt::format("{}: {} table rows, the header says {} (at least 8 needed)", path,
                                         t.correction.size(), points));
  }
  return t;
}

}  // namespace resolver
