#include "daemon/app/daemon_config.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <optional>
#include <sstream>
#include <fmt/format.h>
#include <toml++/toml.h>

#include "daemon/core/discovery/model_discovery.h"
#include "daemon/core/angles.h"
#include "daemon/core/estimation/estimator_models.h"
#include "daemon/decode/signal_units.h"

namespace resolver {

std::string default_dbc_path() { return "proto/resolver_bench.dbc (built into resolverd)"; }

namespace {

constexpr std::int64_t kMaxExtendedCanId = 0x1FFFFFFF;
/// [estimator] max_order's largest value: the fit's result is a Model of the catalog
/// (estimator_models.h), whose harmonics effect ends at k20, error order 19; an order
/// above it would be fitted but neither compensated nor published. (Speed is not the
/// limit: at 64, 129 parameters, a 2 s log of the default bench replayed at 54k
/// frames/s on the project's machine.)
constexpr int kMaxFourierOrder = kFourierModelMaxOrder;
/// [Hz] Sample and row rates: above 1 MHz two samples share a microsecond stamp;
/// below 1 Hz no bench samples a resolver (1e-300 made every period 1e300 s, and
/// every window "0 moving" over 3.2e+303 s).
constexpr double kMinRateHz = 1.0;
constexpr double kMaxRateHz = 1e6;

std::string where(const std::string& source, const toml::node& node) {
  const auto& src = node.source();
  return source + ":" + std::to_string(src.begin.line);
}

/// A rate option: 0 (unset) or kMinRateHz..kMaxRateHz, NaN and inf refused too.
void check_rate(const toml::table& t, std::string_view key, double value, const std::string& section,
                const std::string& zero_means, const std::string& s) {
  if (value == 0.0 || (value >= kMinRateHz && value <= kMaxRateHz)) return;
  const toml::node* node = t.get(key);
  throw ConfigError((node != nullptr ? where(s, *node) : s) + ": [" + section + "] " + std::string(key) +
                    " must be 1 .. 1e6 Hz (" + zero_means + "), got " + fmt::format("{:g}", value));
}

/// Rejects keys of `table` that are not in `allowed` (typos must not be silent).
void check_keys(const toml::table& table, const std::string& section, std::initializer_list<std::string_view> allowed,
                const std::string& source) {
  for (const auto& [key, node] : table) {
    bool ok = false;
    for (auto a : allowed) ok = ok || a == key.str();
    if (!ok) {
      std::string list;
      for (auto a : allowed) {
        if (!list.empty()) list += ", ";
        list += a;
      }
      std::string msg = where(source, node);
      msg += ": unknown key '";
      msg += key.str();
      msg += "' in [" + section + "]; valid keys: ";
      msg += list;
      throw ConfigError(msg);
    }
  }
}

template <typename T>
void read(const toml::table& table, std::string_view key, T& out, const std::string& source,
          const std::string& section) {
  const toml::node* node = table.get(key);
  if (node == nullptr) return;
  if constexpr (std::is_same_v<T, std::string>) {
    if (auto v = node->value<std::string>()) { out = *v; return; }
    throw ConfigError(where(source, *node) + ": [" + section + "] " + std::string(key) + " must be a string");
  } else if constexpr (std::is_same_v<T, bool>) {
    if (auto v = node->value<bool>()) { out = *v; return; }
    throw ConfigError(where(source, *node) + ": [" + section + "] " + std::string(key) + " must be true or false");
  } else if constexpr (std::is_same_v<T, int>) {
    if (node->is_integer()) {
      // Out of int range would wrap silently (4294967299 -> 3): refuse it instead.
      const std::int64_t v = *node->value<std::int64_t>();
      if (v >= std::numeric_limits<int>::min() && v <= std::numeric_limits<int>::max()) {
        out = static_cast<int>(v);
        return;
      }
      throw ConfigError(where(source, *node) + ": [" + section + "] " + std::string(key) + " = " + std::to_string(v) +
                        " is out of range");
    }
    throw ConfigError(where(source, *node) + ": [" + section + "] " + std::string(key) + " must be an integer");
  } else {
    if (auto v = node->value<double>()) { out = *v; return; }
    throw ConfigError(where(source, *node) + ": [" + section + "] " + std::string(key) + " must be a number");
  }
}

void require_positive(int value, const char* name, const std::string& source) {
  if (value < 1) throw ConfigError(source + ": " + name + " must be >= 1, got " + std::to_string(value));
}

void read_wake_ids(const toml::table& t, bool& wake_auto, std::vector<std::uint32_t>& ids, const std::string& s) {
  const toml::node* node = t.get("wake_ids");
  if (node == nullptr) return;
  if (const auto text = node->value<std::string>(); text && *text == "auto") {
    wake_auto = true;
    ids.clear();
    return;
  }
  const toml::array* arr = node->as_array();
  if (arr == nullptr) {
    throw ConfigError(where(s, *node) +
                      ": [can] wake_ids must be \"auto\" or an array of CAN IDs, e.g. [0x102] ([] = every frame)");
  }
  wake_auto = false;
  ids.clear();
  for (const auto& item : *arr) {
    const std::optional<std::int64_t> id = item.is_integer() ? item.value<std::int64_t>() : std::nullopt;
    if (!id || *id < 0 || *id > kMaxExtendedCanId) {
      throw ConfigError(where(s, item) + ": [can] wake_ids: each entry must be a CAN ID from 0 to 0x1FFFFFFF");
    }
    ids.push_back(static_cast<std::uint32_t>(*id));
  }
}

std::vector<CustomEffectSpec> read_custom_blocks(const toml::node& node, const std::string& s) {
  const toml::array* blocks = node.as_array();
  if (blocks == nullptr) {
    throw ConfigError(where(s, node) + ": [[model.custom]] must be an array of tables (write [[model.custom]] blocks)");
  }
  std::vector<CustomEffectSpec> out;
  int index = 0;
  for (const auto& b : *blocks) {
    ++index;
    const toml::table* t = b.as_table();
    if (t == nullptr) throw ConfigError(where(s, b) + ": [[model.custom]] entry " + std::to_string(index) + " must be a table");
    check_keys(*t, "model.custom", {"name", "signal", "terms", "description"}, s);
    CustomEffectSpec spec;
    spec.origin = where(s, b) + " [[model.custom]] #" + std::to_string(index);
    read(*t, "name", spec.name, s, "model.custom");
    read(*t, "signal", spec.signal, s, "model.custom");
    read(*t, "description", spec.description, s, "model.custom");
    const toml::node* terms = t->get("terms");
    if (terms == nullptr || terms->as_array() == nullptr) {
      throw ConfigError(spec.origin + ": terms must be an array of expressions, e.g. terms = [\"sin(4*theta_m)\"]");
    }
    for (const auto& term : *terms->as_array()) {
      const auto text = term.value<std::string>();
      if (!text) throw ConfigError(where(s, term) + ": [[model.custom]] terms: each entry must be a string");
      spec.terms.push_back(*text);
    }
    if (spec.name.empty()) throw ConfigError(spec.origin + ": name = \"...\" is required");
    out.push_back(std::move(spec));
  }
  return out;
}

void read_model_section(const toml::table& t, ModelFitOptions& m, const std::string& s) {
  check_keys(t, "model", {"enabled", "effects", "window_revolutions", "candidates", "custom"}, s);
  read(t, "enabled", m.enabled, s, "model");
  read(t, "candidates", m.candidates, s, "model");
  read(t, "window_revolutions", m.window_revolutions, s, "model");
  if (!(m.window_revolutions >= 2.0) || !std::isfinite(m.window_revolutions)) {
    throw ConfigError(s + ": [model] window_revolutions must be a number >= 2 (the fit needs two revolutions)");
  }
  if (const toml::node* c = t.get("custom")) {
    m.custom = read_custom_blocks(*c, s);
    try {
      m.customs = std::make_shared<const CustomEffects>(m.custom);
    } catch (const std::invalid_argument& e) {
      throw ConfigError(e.what());
    }
  }
  const toml::node* e = t.get("effects");
  if (e == nullptr) return;
  const toml::array* arr = e->as_array();
  if (arr == nullptr) {
    throw ConfigError(where(s, *e) + ": [model] effects must be an array of effect names, e.g. [\"amplitude_imbalance\"]");
  }
  m.effects.clear();
  for (const auto& item : *arr) {
    const auto name = item.value<std::string>();
    if (!name) throw ConfigError(where(s, item) + ": [model] effects: each entry must be a string");
    try {
      (void)ModelSpec::parse(std::vector<std::string>{*name}, m.customs.get());
    } catch (const std::invalid_argument& err) {
      throw ConfigError(where(s, item) + ": [model] effects: " + err.what());
    }
    m.effects.push_back(*name);
  }
}

void read_health_section(const toml::table& t, DaemonConfig& c, const std::string& s) {
  check_keys(t, "health",
             {"full_scale", "loss_of_signal_fraction", "degradation_low_fraction", "degradation_high_fraction",
              "degradation_mismatch", "loss_of_tracking_deg", "overspeed_rad_per_sample", "stopped_below_hz",
              "outlier_sigmas", "block_s"},
             s);
  SignalHealthConfig& h = c.health;
  double full_scale = 0.0;
  read(t, "full_scale", full_scale, s, "health");
  if (!(full_scale >= 0.0) || !std::isfinite(full_scale)) {
    throw ConfigError(s + ": [health] full_scale must be a finite number >= 0 (0 = from the DBC signal's range)");
  }
  if (full_scale > 0.0) {
    h.full_scale = full_scale;
    h.clip_margin = 0.5;  // half a count: a config full scale is in counts
    c.health_full_scale_set = true;
  }
  double lot_deg = rad_to_deg(h.loss_of_tracking_rad);
  read(t, "loss_of_signal_fraction", h.loss_of_signal_fraction, s, "health");
  read(t, "degradation_low_fraction", h.degradation_low_fraction, s, "health");
  read(t, "degradation_high_fraction", h.degradation_high_fraction, s, "health");
  read(t, "degradation_mismatch", h.degradation_mismatch, s, "health");
  read(t, "loss_of_tracking_deg", lot_deg, s, "health");
  read(t, "overspeed_rad_per_sample", h.overspeed_rad_per_sample, s, "health");
  read(t, "stopped_below_hz", h.stopped_below_hz, s, "health");
  read(t, "outlier_sigmas", h.outlier_sigmas, s, "health");
  read(t, "block_s", h.block_s, s, "health");
  // Written so NaN fails every check (NaN compares false).
  auto in = [&s](double v, double lo, double hi, const char* key, const char* what) {
    if (!(v > lo && v <= hi)) {
      throw ConfigError(s + ": [health] " + key + " must be " + what + ", got " + std::to_string(v));
    }
  };
  in(h.loss_of_signal_fraction, 0.0, 1.0, "loss_of_signal_fraction", "in (0, 1] (a share of full scale)");
  in(h.degradation_low_fraction, 0.0, 1.0, "degradation_low_fraction", "in (0, 1] (a share of full scale)");
  in(h.degradation_high_fraction, 0.0, 2.0, "degradation_high_fraction", "in (0, 2] (a share of full scale)");
  if (!(h.loss_of_signal_fraction <= h.degradation_low_fraction &&
        h.degradation_low_fraction < h.degradation_high_fraction)) {
    throw ConfigError(s + ": [health] needs loss_of_signal_fraction <= degradation_low_fraction < "
                          "degradation_high_fraction");
  }
  in(h.degradation_mismatch, 0.0, 10.0, "degradation_mismatch", "in (0, 10] (a share of the mean amplitude)");
  in(lot_deg, 0.0, 180.0, "loss_of_tracking_deg", "in (0, 180] degrees (180 = never)");
  h.loss_of_tracking_rad = lot_deg * kPi / 180.0;
  in(h.overspeed_rad_per_sample, 0.0, kPi, "overspeed_rad_per_sample", "in (0, pi] (pi per sample aliases)");
  if (!(h.stopped_below_hz >= 0.0 && std::isfinite(h.stopped_below_hz))) {
    throw ConfigError(s + ": [health] stopped_below_hz must be a finite number >= 0 (0 = never)");
  }
  in(h.outlier_sigmas, 2.0, 1e6, "outlier_sigmas", "above 2 (robust standard deviations)");
  in(h.block_s, 0.0, 10.0, "block_s", "in (0, 10] seconds");
}

/// A column reference: a name (string) or a 1-based index (integer).
ColumnRef read_column(const toml::node& node, const std::string& what, bool have_names, const std::string& s) {
  if (node.is_integer()) {
    const std::int64_t i = *node.value<std::int64_t>();
    if (i < 1 || i > 100000) throw ConfigError(where(s, node) + ": " + what + ": a column index counts from 1, got " + std::to_string(i));
    return ColumnRef{"", static_cast<int>(i)};
  }
  const auto name = node.value<std::string>();
  if (!name || name->empty()) {
    throw ConfigError(where(s, node) + ": " + what + " must be a column name (string) or a 1-based column index (integer)");
  }
  if (!have_names) {
    throw ConfigError(where(s, node) + ": " + what + " = \"" + *name +
                      "\" names a column, but [input.csv] column_names = false: give its 1-based index instead");
  }
  return ColumnRef{*name, 0};
}

bool is_angle_role(Role r) { return r == Role::kRdAngle || r == Role::kRefAngle; }
bool is_current_role(Role r) { return r == Role::kIA || r == Role::kIB || r == Role::kIC; }

RowRole read_csv_column(Role role, const toml::node& node, bool have_names, const std::string& s) {
  const std::string what = "[input.csv.columns] " + std::string(role_name(role));
  const toml::table* t = node.as_table();
  if (t == nullptr) {
    throw ConfigError(where(s, node) + ": " + what + " must be an inline table, e.g. { column = \"Resolver\", unit = \"deg\" }");
  }
  check_keys(*t, "input.csv.columns." + std::string(role_name(role)), {"column", "unit", "scale", "offset", "full_scale", "divide"}, s);
  RowRole r;
  const toml::node* col = t->get("column");
  if (col == nullptr) throw ConfigError(where(s, node) + ": " + what + " needs column = name or 1-based index");
  r.column = read_column(*col, what + " column", have_names, s);
  read(*t, "unit", r.unit, s, "input.csv.columns");
  read(*t, "scale", r.scale, s, "input.csv.columns");
  read(*t, "offset", r.offset, s, "input.csv.columns");
  double full_scale = 0.0;
  read(*t, "full_scale", full_scale, s, "input.csv.columns");
  read(*t, "divide", r.divide, s, "input.csv.columns");
  if (!std::isfinite(r.scale) || r.scale == 0.0 || !std::isfinite(r.offset)) {
    throw ConfigError(where(s, node) + ": " + what + ": scale must be a finite non-zero number and offset finite");
  }
  const bool sincos = role == Role::kSin || role == Role::kCos;
  if (t->get("full_scale") != nullptr && r.unit != "counts" && !sincos) {
    throw ConfigError(where(s, node) + ": " + what + ": full_scale goes with unit = \"counts\" (or sin, cos)");
  }
  if (sincos) {
    if (t->get("full_scale") != nullptr && (!(full_scale > 0.0) || !std::isfinite(full_scale))) {
      throw ConfigError(where(s, node) + ": " + what + ": full_scale (the largest |value| the ADC reaches) must be > 0");
    }
    r.full_scale = full_scale;
  }
  if (t->get("divide") != nullptr && (!is_angle_role(role) || !(r.divide > 0.0) || !std::isfinite(r.divide))) {
    throw ConfigError(where(s, node) + ": " + what +
                      ": divide = N (an angle unwrapped and divided by N, > 0) is for rd_angle and ref_angle only");
  }
  if (is_angle_role(role)) {
    if (r.unit == "counts") {
      if (!(full_scale > 0.0) || !std::isfinite(full_scale)) {
        throw ConfigError(where(s, node) + ": " + what + ": unit = \"counts\" needs full_scale = counts per revolution (e.g. 65536)");
      }
      r.to_role_unit = kTwoPi / full_scale;
    } else if (const auto f = angle_unit_to_rad(r.unit)) {
      r.to_role_unit = *f;
    } else {
      throw ConfigError(where(s, node) + ": " + what + ": unit " + quote_unit(r.unit) + " is not an angle unit; one of: " +
                        std::string(kAngleUnitList) + ", counts (with full_scale)");
    }
  } else if (is_current_role(role)) {
    const auto f = current_unit_to_amps(r.unit);
    if (!f) {
      throw ConfigError(where(s, node) + ": " + what + ": unit " + quote_unit(r.unit) + " is not a current unit; one of: " +
                        std::string(kCurrentUnitList));
    }
    r.to_role_unit = *f;
  }
  return r;
}

void read_csv_section(const toml::table& t, CsvInputConfig& c, const std::string& s) {
  check_keys(t, "input.csv",
             {"delimiter", "decimal", "header_lines", "column_names", "time_column", "time_unit", "row_rate_hz", "columns"},
             s);
  std::string delimiter = "auto";
  read(t, "delimiter", delimiter, s, "input.csv");
  if (delimiter == "auto") c.format.delimiter = CsvFormat::Delimiter::kAuto;
  else if (delimiter == ",") c.format.delimiter = CsvFormat::Delimiter::kComma;
  else if (delimiter == ";") c.format.delimiter = CsvFormat::Delimiter::kSemicolon;
  else if (delimiter == "tab" || delimiter == "\t") c.format.delimiter = CsvFormat::Delimiter::kTab;
  else if (delimiter == "space" || delimiter == " ") c.format.delimiter = CsvFormat::Delimiter::kSpace;
  else throw ConfigError(s + ": [input.csv] delimiter must be \",\", \";\", \"tab\", \"space\" or \"auto\", got \"" + delimiter + "\"");
  std::string decimal = ".";
  read(t, "decimal", decimal, s, "input.csv");
  if (decimal != "." && decimal != ",") throw ConfigError(s + ": [input.csv] decimal must be \".\" or \",\", got \"" + decimal + "\"");
  c.format.decimal = decimal[0];
  if (c.format.decimal == ',' && c.format.delimiter == CsvFormat::Delimiter::kComma) {
    throw ConfigError(s + ": [input.csv] decimal = \",\" with delimiter = \",\" cannot be told apart; the export uses \";\" or tabs");
  }
  if (const toml::node* h = t.get("header_lines")) {
    if (const auto text = h->value<std::string>(); text && *text == "auto") {
      c.format.skip_until_numbers = true;
    } else {
      read(t, "header_lines", c.format.header_lines, s, "input.csv");
      if (c.format.header_lines < 0) throw ConfigError(where(s, *h) + ": [input.csv] header_lines must be >= 0 or \"auto\"");
    }
  }
  read(t, "column_names", c.format.column_names, s, "input.csv");
  if (const toml::node* tc = t.get("time_column")) {
    if (const auto text = tc->value<std::string>(); !(text && text->empty())) {
      c.map.time = read_column(*tc, "[input.csv] time_column", c.format.column_names, s);
    }
  }
  std::string unit = "s";
  read(t, "time_unit", unit, s, "input.csv");
  if (unit == "s") c.map.time_unit = TimeUnit::kSeconds;
  else if (unit == "ms") c.map.time_unit = TimeUnit::kMilliseconds;
  else if (unit == "us") c.map.time_unit = TimeUnit::kMicroseconds;
  else if (unit == "filetime") c.map.time_unit = TimeUnit::kFiletime;
  else throw ConfigError(s + ": [input.csv] time_unit must be \"s\", \"ms\", \"us\" or \"filetime\", got \"" + unit + "\"");
  read(t, "row_rate_hz", c.map.row_rate_hz, s, "input.csv");
  check_rate(t, "row_rate_hz", c.map.row_rate_hz, "input.csv", "rows per second of an export without a time column", s);
  if (c.map.time && c.map.row_rate_hz > 0.0) {
    throw ConfigError(s + ": [input.csv] row_rate_hz is for exports without a time column; this one names time_column");
  }
  if (const toml::node* cols = t.get("columns")) {
    const toml::table* table = cols->as_table();
    if (table == nullptr) throw ConfigError(where(s, *cols) + ": [input.csv.columns] must be a table");
    for (const auto& [key, node] : *table) {
      const auto role = role_from_name(key.str());
      if (!role) {
        throw ConfigError(where(s, node) + ": [input.csv.columns] unknown role '" + std::string(key.str()) +
                          "'; valid roles: sin, cos, rd_angle, i_a, i_b, i_c, ref_angle");
      }
      c.map.roles[static_cast<std::size_t>(*role)] = read_csv_column(*role, node, c.format.column_names, s);
    }
    const bool has_rd = c.map.roles[static_cast<std::size_t>(Role::kRdAngle)].has_value();
    const bool has_sincos = c.map.roles[static_cast<std::size_t>(Role::kSin)].has_value() &&
                            c.map.roles[static_cast<std::size_t>(Role::kCos)].has_value();
    if (!has_rd && !has_sincos) {
      throw ConfigError(s + ": [input.csv.columns] needs rd_angle, or both sin and cos: nothing to estimate an angle from");
    }
    if (!c.map.time && !(c.map.row_rate_hz > 0.0)) {
      throw ConfigError(s + ": [input.csv] has no time_column: set row_rate_hz (rows per second) so samples have a time");
    }
  }
}

void read_input_section(const toml::table& t, DaemonConfig& c, const std::string& s) {
  check_keys(t, "input", {"format", "csv"}, s);
  std::string format = "auto";
  read(t, "format", format, s, "input");
  if (format != "auto") {
    c.input_format = log_format_from_name(format);
    if (!c.input_format) {
      throw ConfigError(s + ": [input] format must be \"auto\", \"candump\", \"asc\" or \"csv\", got \"" + format + "\"");
    }
  }
  if (const toml::node* csv = t.get("csv")) {
    if (!csv->is_table()) throw ConfigError(where(s, *csv) + ": [input.csv] must be a table");
    read_csv_section(*csv->as_table(), c.csv, s);
  }
}

void read_lcm_section(const toml::table& t, DaemonConfig& c, const std::string& s) {
  check_keys(t, "lcm", {"url"}, s);
  read(t, "url", c.lcm_url, s, "lcm");
}

void read_can_section(const toml::table& t, DaemonConfig& c, const std::string& s) {
  check_keys(t, "can", {"receive_buffer_bytes", "wake_ids"}, s);
  read(t, "receive_buffer_bytes", c.can.receive_buffer_bytes, s, "can");
  if (c.can.receive_buffer_bytes < 0) throw ConfigError(s + ": [can] receive_buffer_bytes must be >= 0");
  read_wake_ids(t, c.can.wake_auto, c.can.wake_ids, s);
}

void read_channels_section(const toml::table& t, DaemonConfig& c, const std::string& s) {
  check_keys(t, "channels", {"angle", "dq", "estimate", "model_fit", "health"}, s);
  read(t, "angle", c.channels.angle, s, "channels");
  read(t, "dq", c.channels.dq, s, "channels");
  read(t, "estimate", c.channels.estimate, s, "channels");
  read(t, "model_fit", c.channels.model_fit, s, "channels");
  read(t, "health", c.channels.health, s, "channels");
}

void read_output_section(const toml::table& t, DaemonConfig& c, const std::string& s) {
  check_keys(t, "output", {"angle_decimation", "dq_decimation", "ripple_revolutions"}, s);
  read(t, "ripple_revolutions", c.ripple_revolutions, s, "output");
  require_positive(c.ripple_revolutions, "[output] ripple_revolutions", s);
  read(t, "angle_decimation", c.angle_decimation, s, "output");
  read(t, "dq_decimation", c.dq_decimation, s, "output");
  require_positive(c.angle_decimation, "[output] angle_decimation", s);
  require_positive(c.dq_decimation, "[output] dq_decimation", s);
}

void read_bench_section(const toml::table& t, DaemonConfig& c, const std::string& s) {
  check_keys(t, "bench", {"p_r", "p", "rd_bits", "use_bench_info", "sample_rate_hz", "time_source", "reference_aligned"}, s);
  read(t, "sample_rate_hz", c.bench.sample_rate_hz, s, "bench");
  // Written so NaN fails too (found by fuzzing: NaN < 0 is false).
  check_rate(t, "sample_rate_hz", c.bench.sample_rate_hz, "bench", "0 = take it from BENCH_INFO", s);
  std::string time_source = "counter";
  read(t, "time_source", time_source, s, "bench");
  if (time_source != "counter" && time_source != "frame") {
    throw ConfigError(s + ": [bench] time_source must be \"counter\" or \"frame\", got \"" + time_source + "\"");
  }
  c.bench.time_from_counter = time_source == "counter";
  read(t, "p_r", c.bench.p_r, s, "bench");
  read(t, "p", c.bench.p, s, "bench");
  read(t, "rd_bits", c.bench.rd_bits, s, "bench");
  read(t, "use_bench_info", c.bench.use_bench_info, s, "bench");
  read(t, "reference_aligned", c.bench.reference_aligned, s, "bench");
  // 1..255, as BENCH_INFO and resolver-sim carry them: p_r = 2147483647 on a real
  // log gave "model: converged over 2856153251 revolutions".
  for (const auto& [key, value] : {std::pair<const char*, int>{"p_r", c.bench.p_r}, {"p", c.bench.p}}) {
    if (value < 1 || value > 255) {
      const toml::node* node = t.get(key);
      throw ConfigError((node != nullptr ? where(s, *node) : s) + ": [bench] " + key + " must be 1..255 (" +
                        (std::string_view(key) == "p_r" ? "resolver" : "motor") +
                        " pole pairs, as BENCH_INFO carries them), got " + std::to_string(value));
    }
  }
  if (c.bench.rd_bits < 1 || c.bench.rd_bits > 16) {
    throw ConfigError(s + ": [bench] rd_bits must be 1..16 (the rd_angle signal is 16 bits), got " +
                      std::to_string(c.bench.rd_bits));
  }
}

/// [layout.signals]: a user map replaces the default one entirely, roles not named are unmapped.
void read_layout_signals(const toml::node& sig, SignalMap& map, const std::string& s) {
  if (!sig.is_table()) throw ConfigError(where(s, sig) + ": [layout.signals] must be a table");
  map.roles = {};
  for (const auto& [key, node] : *sig.as_table()) {
    const auto role = role_from_name(key.str());
    if (!role) {
      throw ConfigError(where(s, node) + ": [layout.signals] unknown role '" + std::string(key.str()) +
                        "'; valid roles: sin, cos, rd_angle, i_a, i_b, i_c, ref_angle");
    }
    const auto value = node.value<std::string>();
    const auto dot = value ? value->find('.') : std::string::npos;
    if (!value || dot == std::string::npos || dot == 0 || dot + 1 == value->size()) {
      throw ConfigError(where(s, node) + ": [layout.signals] " + std::string(key.str()) +
                        " must be \"MESSAGE.signal\" as named in the DBC");
    }
    map.roles[static_cast<std::size_t>(*role)] = SignalRef{value->substr(0, dot), value->substr(dot + 1)};
  }
}

void read_layout_section(const toml::table& t, DaemonConfig& c, const std::string& s) {
  check_keys(t, "layout",
             {"dbc", "counter_signal", "crc_signal", "crc", "bench_info_message", "max_counter_delta", "signals"}, s);
  read(t, "dbc", c.dbc_path, s, "layout");
  // A relative DBC path belongs with the config that names it, wherever resolverd is started from.
  if (!c.dbc_path.empty() && std::filesystem::path(c.dbc_path).is_relative()) {
    c.dbc_path = (std::filesystem::path(s).parent_path() / c.dbc_path).string();
  }
  read(t, "counter_signal", c.signal_map.counter_signal, s, "layout");
  read(t, "crc_signal", c.signal_map.crc_signal, s, "layout");
  read(t, "bench_info_message", c.signal_map.bench_info_message, s, "layout");
  read(t, "max_counter_delta", c.max_counter_delta, s, "layout");
  require_positive(c.max_counter_delta, "[layout] max_counter_delta", s);
  std::string crc = "j1850_bench";
  read(t, "crc", crc, s, "layout");
  if (crc == "j1850_bench") {
    c.signal_map.crc = CrcAlgorithm::kBenchJ1850;
  } else if (crc == "none") {
    c.signal_map.crc = CrcAlgorithm::kNone;
  } else {
    throw ConfigError(where(s, *t.get("crc")) + ": [layout] crc must be \"j1850_bench\" or \"none\", got \"" + crc + "\"");
  }
  if (const toml::node* sig = t.get("signals")) read_layout_signals(*sig, c.signal_map, s);
}

/// [estimator] harmonics: the orders sincos_least_squares fits besides the first.
void read_estimator_harmonics(const toml::node& h, std::vector<int>& harmonics, const std::string& s) {
  const toml::array* arr = h.as_array();
  if (arr == nullptr) throw ConfigError(where(s, h) + ": [estimator] harmonics must be an array of orders, e.g. [3]");
  harmonics.clear();
  for (const auto& el : *arr) {
    // is_integer first: value<int64_t>() of a float like 1e90 converts out of range
    // (undefined behaviour; fuzz finding F4).
    const auto n = el.is_integer() ? el.value<std::int64_t>() : std::nullopt;
    if (!n || *n < 2 || *n > 16) {
      throw ConfigError(where(s, h) + ": [estimator] harmonics: orders must be integers 2..16");
    }
    harmonics.push_back(static_cast<int>(*n));
  }
}

void read_estimator_section(const toml::table& t, DaemonConfig& c, const std::string& s) {
  check_keys(t, "estimator",
             {"method", "min_revolutions", "max_speed_change", "min_samples_per_revolution", "forgetting",
              "harmonics", "max_order"},
             s);
  read(t, "method", c.estimator_method, s, "estimator");
  double forgetting = 1.0;
  read(t, "forgetting", forgetting, s, "estimator");
  if (!(forgetting > 0.0 && forgetting <= 1.0)) {
    throw ConfigError(s + ": [estimator] forgetting must be in (0, 1], got " + std::to_string(forgetting));
  }
  c.sincos.forgetting = forgetting;
  c.fourier.forgetting = forgetting;
  read(t, "max_order", c.fourier.max_order, s, "estimator");
  // The fit has 2 max_order + 1 parameters, updated every sample at a cost of
  // their square: 2000 ran for minutes on a 2 s log, 2^31 - 1 ended in bad_alloc.
  if (c.fourier.max_order < 1 || c.fourier.max_order > kMaxFourierOrder) {
    throw ConfigError(where(s, *t.get("max_order")) + ": [estimator] max_order must be 1.." +
                      std::to_string(kMaxFourierOrder) + " (the highest harmonic fourier_reference fits; each order "
                      "adds two parameters, updated every sample), got " + std::to_string(c.fourier.max_order));
  }
  if (const toml::node* h = t.get("harmonics")) read_estimator_harmonics(*h, c.sincos.harmonics, s);
  read(t, "min_revolutions", c.hwang.min_revolutions, s, "estimator");
  read(t, "max_speed_change", c.hwang.max_speed_change, s, "estimator");
  read(t, "min_samples_per_revolution", c.hwang.min_samples_per_revolution, s, "estimator");
  const auto method = estimator_from_name(c.estimator_method);
  if (!method) {
    throw ConfigError(s + ": [estimator] method \"" + c.estimator_method +
                      "\" is not available; available: " + estimator_names());
  }
  c.method = *method;
  require_positive(c.hwang.min_revolutions, "[estimator] min_revolutions", s);
  if (!(c.hwang.max_speed_change > 0.0) || !std::isfinite(c.hwang.max_speed_change)) {
    throw ConfigError(s + ": [estimator] max_speed_change must be a finite number > 0");
  }
}

void read_compensation_section(const toml::table& t, DaemonConfig& c, const std::string& s) {
  check_keys(t, "compensation", {"enabled", "domain"}, s);
  read(t, "enabled", c.compensation_enabled, s, "compensation");
  std::string domain = "angle";
  read(t, "domain", domain, s, "compensation");
  if (domain == "angle") {
    c.compensation_domain = CompensationDomain::kAngle;
  } else if (domain == "signal") {
    c.compensation_domain = CompensationDomain::kSignal;
  } else {
    throw ConfigError(s + ": [compensation] domain must be \"angle\" or \"signal\", got \"" + domain + "\"");
  }
}

/// The TOML text as a table; a syntax error names the file, line and column.
toml::table parse_toml(std::string_view text, const std::string& source_name) {
  try {
    return toml::parse(text, source_name);
  } catch (const toml::parse_error& e) {
    throw ConfigError(source_name + ":" + std::to_string(e.source().begin.line) + ":" +
                      std::to_string(e.source().begin.column) + ": TOML syntax error: " + std::string(e.description()));
  }
}

/// The top-level section `name`, null when absent; anything but a table is an error.
const toml::table* section_table(const toml::table& root, const char* name, const std::string& s) {
  const toml::node* n = root.get(name);
  if (n == nullptr) return nullptr;
  if (!n->is_table()) throw ConfigError(where(s, *n) + ": '" + name + "' must be a table ([" + name + "])");
  return n->as_table();
}

}  // namespace

std::optional<LogFormat> log_format_from_name(std::string_view name) {
  if (name == "candump") return LogFormat::kCandump;
  if (name == "asc") return LogFormat::kAsc;
  if (name == "csv") return LogFormat::kCsv;
  return std::nullopt;
}

std::string_view log_format_name(LogFormat format) {
  switch (format) {
    case LogFormat::kCandump: return "candump";
    case LogFormat::kAsc: return "asc";
    case LogFormat::kCsv: return "csv";
  }
  return "candump";
}

LogFormat log_format_for_path(std::string_view path) {
  const auto dot = path.rfind('.');
  const auto slash = path.rfind('/');
  if (dot == std::string_view::npos || (slash != std::string_view::npos && dot < slash)) return LogFormat::kCandump;
  std::string ext(path.substr(dot + 1));
  for (char& ch : ext) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
  if (ext == "asc") return LogFormat::kAsc;
  if (ext == "csv" || ext == "txt" || ext == "tsv" || ext == "dat") return LogFormat::kCsv;
  return LogFormat::kCandump;
}

DaemonConfig parse_daemon_config(std::string_view text, const std::string& source_name) {
  const toml::table root = parse_toml(text, source_name);
  DaemonConfig c;
  c.source = source_name;
  const std::string& s = source_name;
  check_keys(root, "top level",
             {"lcm", "can", "channels", "output", "bench", "layout", "estimator", "compensation", "model", "health",
              "input"},
             s);
  // In this order: the first error found is the one reported.
  if (const auto* t = section_table(root, "lcm", s)) read_lcm_section(*t, c, s);
  if (const auto* t = section_table(root, "can", s)) read_can_section(*t, c, s);
  if (const auto* t = section_table(root, "channels", s)) read_channels_section(*t, c, s);
  if (const auto* t = section_table(root, "output", s)) read_output_section(*t, c, s);
  if (const auto* t = section_table(root, "bench", s)) read_bench_section(*t, c, s);
  if (const auto* t = section_table(root, "layout", s)) read_layout_section(*t, c, s);
  if (const auto* t = section_table(root, "estimator", s)) read_estimator_section(*t, c, s);
  if (const auto* t = section_table(root, "compensation", s)) read_compensation_section(*t, c, s);
  if (const auto* t = section_table(root, "model", s)) read_model_section(*t, c.model, s);
  if (const auto* t = section_table(root, "health", s)) read_health_section(*t, c, s);
  if (const auto* t = section_table(root, "input", s)) read_input_section(*t, c, s);
  if (c.compensation_domain == CompensationDomain::kSignal && c.method != EstimatorMethod::kSinCosLeastSquares) {
    throw ConfigError(s + ": [compensation] domain = \"signal\" needs [estimator] method = \"sincos_least_squares\" "
                          "(only it estimates the sin/cos signal parameters)");
  }
  c.model.reference_aligned = c.bench.reference_aligned;
  return c;
}

DaemonConfig load_daemon_config(const std::string& path) {
  // A directory opens and reads as empty, which would be a config of defaults
  // (e.g. a SIGHUP after the file was replaced by a directory).
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) {
    throw ConfigError("cannot read config file " + path + ": it is a directory, not a file");
  }
  std::ifstream in(path);
  if (!in) throw ConfigError("cannot read config file " + path + ": " + std::strerror(errno));
  std::ostringstream text;
  text << in.rdbuf();
  return parse_daemon_config(text.str(), path);
}

}  // namespace resolver
