#include "tools/model/export_data.h"

#include <fmt/format.h>
#include <matio.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <memory>
#include <stdexcept>
#include <system_error>

#include "daemon/core/angles.h"
#include "daemon/core/errors.h"
#include "tools/model/report_data.h"
#include "tools/model/row_prediction.h"

namespace resolver {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// Adds a column of `n` NaNs; returns its index (references would not survive the next column).
std::size_t add(ExportTable& t, std::string name, std::string unit, std::string description, std::size_t n) {
  t.columns.push_back({std::move(name), std::move(unit), std::move(description), std::vector<double>(n, kNaN)});
  return t.columns.size() - 1;
}

/// The measured, predicted and residual columns of one signal (indices into the table).
struct SignalColumns {
  bool present = false;
  std::size_t measured = 0, model = 0, residual = 0;
};

SignalColumns add_signal(ExportTable& t, const std::string& stem, const std::string& unit_suffix,
                         const std::string& unit, const std::string& what, std::size_t n) {
  const std::string suffix = unit_suffix.empty() ? "" : "_" + unit_suffix;
  SignalColumns c;
  c.present = true;
  c.measured = add(t, stem + suffix, unit, "measured " + what, n);
  c.model = add(t, stem + "_model" + suffix, unit, "the fitted model's prediction of " + what, n);
  c.residual = add(t, stem + "_residual" + suffix, unit, "measured minus model, " + what + " (NaN where not measured)", n);
  return c;
}

void fill(ExportTable& t, const SignalColumns& c, std::size_t i, bool has, double measured, double model) {
  if (!c.present) return;
  t.columns[c.model].values[i] = model;
  if (!has) return;
  t.columns[c.measured].values[i] = measured;
  t.columns[c.residual].values[i] = measured - model;
}

std::string csv_text(std::string_view s) {
  std::string o = "\"";
  for (const char ch : s) o += ch == '"' ? std::string("\"\"") : std::string(1, ch);
  return o + "\"";
}

/// 12 significant digits: the angles to 1e-12 of a turn, far below any floor; NaN as MATLAB and Python spell it.
std::string csv_number(double v) {
  if (std::isnan(v)) return "NaN";
  if (std::isinf(v)) return v > 0 ? "Inf" : "-Inf";
  return fmt::format("{:.12g}", v);
}

class CsvFile {
 public:
  explicit CsvFile(const std::string& path) : path_(path), f_(std::fopen(path.c_str(), "wb")) {
    if (f_ == nullptr) throw std::system_error(errno, std::generic_category(), "cannot write " + path);
  }
  CsvFile(const CsvFile&) = delete;
  CsvFile& operator=(const CsvFile&) = delete;
  ~CsvFile() {
    if (f_ != nullptr) std::fclose(f_);
  }
  void line(const std::string& text) {
    if (std::fwrite(text.data(), 1, text.size(), f_) != text.size() || std::fputc('\n', f_) == EOF) fail();
  }
  void close() {
    std::FILE* f = f_;
    f_ = nullptr;
    if (std::fclose(f) != 0) throw std::system_error(errno, std::generic_category(), "cannot write " + path_);
  }

 private:
  [[noreturn]] void fail() const { throw std::system_error(errno, std::generic_category(), "cannot write " + path_); }
  std::string path_;
  std::FILE* f_;
};

// ---- MAT-5 through matio ----------------------------------------------------------------

struct VarFree {
  void operator()(matvar_t* v) const { Mat_VarFree(v); }
};
using Var = std::unique_ptr<matvar_t, VarFree>;

Var mat_checked(matvar_t* v, std::string_view what) {
  if (v == nullptr) throw std::runtime_error(fmt::format("matio could not create {}", what));
  return Var(v);
}

Var mat_column(const std::vector<double>& values) {
  std::size_t dims[2] = {values.size(), 1};
  // matio copies the data (opt 0): the variable owns what it frees.
  return mat_checked(Mat_VarCreate(nullptr, MAT_C_DOUBLE, MAT_T_DOUBLE, 2, dims,
                                   const_cast<double*>(values.data()), 0),
                     "a column");
}

Var mat_text(const std::string& text) {
  std::size_t dims[2] = {1, text.size()};
  return mat_checked(Mat_VarCreate(nullptr, MAT_C_CHAR, MAT_T_UTF8, 2, dims, const_cast<char*>(text.data()), 0),
                     "a text");
}

Var mat_cells(const std::vector<std::string>& texts) {
  std::size_t dims[2] = {texts.size(), 1};
  Var cell = mat_checked(Mat_VarCreate(nullptr, MAT_C_CELL, MAT_T_CELL, 2, dims, nullptr, 0), "a cell array");
  for (std::size_t i = 0; i < texts.size(); ++i) Mat_VarSetCell(cell.get(), static_cast<int>(i), mat_text(texts[i]).release());
  return cell;
}

/// A 1 x 1 struct with the given fields (the struct takes them over).
Var mat_struct(const char* name, std::vector<std::pair<std::string, Var>> fields) {
  std::vector<const char*> names;
  names.reserve(fields.size());
  for (const auto& f : fields) names.push_back(f.first.c_str());
  std::size_t dims[2] = {1, 1};
  Var s = mat_checked(Mat_VarCreateStruct(name, 2, dims, names.data(), static_cast<unsigned>(names.size())),
                      fmt::format("the struct {}", name));
  for (auto& f : fields) Mat_VarSetStructFieldByName(s.get(), f.first.c_str(), 0, f.second.release());
  return s;
}

// ---- the table ----------------------------------------------------------------------

constexpr std::size_t kNoColumn = static_cast<std::size_t>(-1);

/// Sets row i of `column` (nothing for kNoColumn: a signal no sample carries).
void set(ExportTable& t, std::size_t column, std::size_t i, double v) {
  if (column != kNoColumn) t.columns[column].values[i] = v;
}

/// The columns every row has: time, angles, speed and the row's part in the fit.
struct RowColumns {
  std::size_t time, theta, theta_m, theta_e, omega, rpm, direction, moving, outlier, excluded, fitted, fold;
};

RowColumns add_row_columns(ExportTable& t, const PreparedLog& log, std::size_t n) {
  RowColumns c{};
  c.time = add(t, "t_s", "s", "time from the log's first sample with an angle", n);
  c.theta = add(t, "theta_rad", "rad",
                log.reference ? "true resolver electrical angle (reference encoder x p_r), wrapped to [0, 2 pi)"
                              : "resolver electrical angle, speed-smoothed ideal (no reference), wrapped to [0, 2 pi)",
                n);
  c.theta_m = add(t, "theta_m_rad", "rad", "true mechanical angle, wrapped to [0, 2 pi)", n);
  c.theta_e = add(t, "theta_e_rad", "rad", "true motor electrical angle p theta_m, wrapped to [0, 2 pi)", n);
  c.omega = add(t, "omega_rad_s", "rad/s", "resolver electrical speed (signed)", n);
  c.rpm = add(t, "speed_rpm", "r/min", "mechanical speed (signed)", n);
  c.direction = add(t, "direction", "1", "+1 forward, -1 backward (held through a standstill)", n);
  c.moving = add(t, "moving", "0/1", "the rotor moves (standstill samples enter no fit)", n);
  c.outlier = add(t, "outlier", "0/1", "an impulsive sample, kept out of the fit and the floors", n);
  c.excluded = add(t, "excluded", "0/1", "left out by --direction, or unusable without a reference", n);
  c.fitted = add(t, "fitted", "0/1", "in the fit: moving, not an outlier, not excluded", n);
  c.fold = add(t, "fold", "1/2", "held-back validation fold", n);
  return c;
}

void fill_row_columns(ExportTable& t, const RowColumns& c, const PreparedLog& log, std::size_t i) {
  const FitRow& r = log.rows[i];
  const SignatureRow& s = r.sig;
  set(t, c.time, i, s.t);
  set(t, c.theta, i, wrap_2pi(s.theta));
  set(t, c.theta_m, i, wrap_2pi(s.theta_m));
  set(t, c.theta_e, i, wrap_2pi(log.p * s.theta_m));
  set(t, c.omega, i, s.omega);
  set(t, c.rpm, i, s.omega / log.p_r * 60.0 / kTwoPi);
  set(t, c.direction, i, s.direction);
  set(t, c.moving, i, r.has(FitRow::kMoving) ? 1.0 : 0.0);
  set(t, c.outlier, i, r.has(FitRow::kOutlier) ? 1.0 : 0.0);
  set(t, c.excluded, i, r.has(FitRow::kExcluded) ? 1.0 : 0.0);
  set(t, c.fitted, i, r.fitted() ? 1.0 : 0.0);
  set(t, c.fold, i, r.has(FitRow::kFoldB) ? 2.0 : 1.0);
}

/// The decoded sample behind row i.
const Sample& sample_of(const DiscoveryInput& input, const PreparedLog& log, std::size_t i) {
  return input.samples.at(log.sample_of_row.at(i));
}

/// The raw signals behind each row, as decoded (daemon/core/sample.h), a column per
/// signal any row's sample carries (kNoColumn for the others).
struct RawColumns {
  std::size_t sin, cos, rd, ref, ia, ib, ic;
};

RawColumns add_raw_columns(ExportTable& t, const DiscoveryInput& input, const PreparedLog& log, std::size_t n) {
  bool any_rd = false, any_sc = false, any_ref = false, any_cur = false;
  for (std::size_t i = 0; i < n; ++i) {
    const Sample& x = sample_of(input, log, i);
    any_rd = any_rd || x.has_rd;
    any_sc = any_sc || x.has_sincos;
    any_ref = any_ref || x.has_ref;
    any_cur = any_cur || x.has_currents;
  }
  const auto add_if = [&](bool present, const char* name, const char* unit, const char* description) {
    return present ? add(t, name, unit, description, n) : kNoColumn;
  };
  RawColumns c{};
  c.sin = add_if(any_sc, "sin_raw", "counts", "sin envelope as decoded (ADC counts; a scope export's own unit)");
  c.cos = add_if(any_sc, "cos_raw", "counts", "cos envelope as decoded (ADC counts; a scope export's own unit)");
  c.rd = add_if(any_rd, "theta_rd_rad", "rad", "R/D converter angle as decoded, resolver electrical, in [0, 2 pi)");
  c.ref = add_if(any_ref, "theta_ref_m_rad", "rad", "reference encoder angle as decoded, mechanical, in [0, 2 pi)");
  c.ia = add_if(any_cur, "i_a_a", "A", "measured phase current a");
  c.ib = add_if(any_cur, "i_b_a", "A", "measured phase current b");
  c.ic = add_if(any_cur, "i_c_a", "A", "measured phase current c");
  return c;
}

void fill_raw_columns(ExportTable& t, const RawColumns& c, const Sample& x, std::size_t i) {
  if (x.has_sincos) {
    set(t, c.sin, i, x.sin);
    set(t, c.cos, i, x.cos);
  }
  if (x.has_rd) set(t, c.rd, i, x.theta_rd);
  if (x.has_ref) set(t, c.ref, i, x.theta_m_ref);
  if (x.has_currents) {
    set(t, c.ia, i, x.i_a);
    set(t, c.ib, i, x.i_b);
    set(t, c.ic, i, x.i_c);
  }
}

/// Measured, model and residual columns of each signal the log has.
struct FittedColumns {
  SignalColumns rd, sa, sr, d, q;
};

FittedColumns add_fitted_columns(ExportTable& t, const PreparedLog& log, std::size_t n) {
  FittedColumns c;
  if (log.rd) c.rd = add_signal(t, "eps_rd", "rad", "rad", "position error theta - theta_rd of the R/D angle", n);
  if (log.sincos) {
    c.sa = add_signal(t, "eps_sc", "rad", "rad", "position error theta - atan2(sin, cos) of the envelopes", n);
    c.sr = add_signal(t, "radius_dev", "", "1", "envelope radius / median amplitude - 1", n);
  }
  if (log.currents) {
    c.d = add_signal(t, "i_d", "a", "A", "i_d in the frame of the true theta_e", n);
    c.q = add_signal(t, "i_q", "a", "A", "i_q in the frame of the true theta_e", n);
  }
  return c;
}

void fill_fitted_columns(ExportTable& t, const FittedColumns& c, const FitRow& r, const SignalValues& p,
                         std::size_t i) {
  fill(t, c.rd, i, r.has(FitRow::kHasRd), r.y_rd, p.rd);
  fill(t, c.sa, i, r.has(FitRow::kHasSc), r.y_sa, p.sa);
  fill(t, c.sr, i, r.has(FitRow::kHasSc), r.y_sr, p.sr);
  fill(t, c.d, i, r.has(FitRow::kHasCur), r.y_d, p.d);
  fill(t, c.q, i, r.has(FitRow::kHasCur), r.y_q, p.q);
}

/// The table's info: the log, the model, the bench and the fit's summary.
std::vector<std::pair<std::string, std::variant<double, std::string>>> export_info(const PreparedLog& log,
                                                                                   const ModelFit& fit,
                                                                                   std::string_view log_path) {
  return {
      {"log", std::string(log_path)},
      {"model", fit.effects.empty() ? std::string("(nuisance only)") : fmt::format("{}", fmt::join(fit.effects, ","))},
      {"p_r", static_cast<double>(log.p_r)},
      {"p", static_cast<double>(log.p)},
      {"angle_source", log.reference ? "reference encoder" : "self-calibrated ideal angle (no reference)"},
      {"residual_rms_rad", fit.residual_rms_rad},
      {"noise_floor_rad", fit.noise_floor_rad},
      {"fold_rule", log.fold_rule},
      {"standard_errors", std_error_basis(fit)},
      {"prediction", "the model's effects at the fitted values plus the constants fitted beside them (the dq "
                     "operating point, the envelopes' gain, an angle offset without a reference)"},
  };
}

}  // namespace

ExportTable export_table(const DiscoveryInput& input, const PreparedLog& log, const ModelFit& fit,
                         std::string_view log_path) {
  ExportTable t;
  const std::size_t n = log.rows.size();
  const RowColumns row_columns = add_row_columns(t, log, n);
  const RawColumns raw_columns = add_raw_columns(t, input, log, n);
  const FittedColumns fitted_columns = add_fitted_columns(t, log, n);
  const RowPredictor predict(log, fit.model);
  for (std::size_t i = 0; i < n; ++i) {
    fill_row_columns(t, row_columns, log, i);
    fill_raw_columns(t, raw_columns, sample_of(input, log, i), i);
    fill_fitted_columns(t, fitted_columns, log.rows[i], predict(log.rows[i]), i);
  }
  t.params = fit.params;
  for (ModelParameter& p : t.params) p.unit = report::bare_unit(p.unit);
  t.info = export_info(log, fit, log_path);
  return t;
}

std::string params_csv_path(const std::string& csv_path) {
  const std::size_t slash = csv_path.find_last_of('/');
  const std::size_t dot = csv_path.find_last_of('.');
  const bool has_ext = dot != std::string::npos && (slash == std::string::npos || dot > slash + 1);
  return (has_ext ? csv_path.substr(0, dot) : csv_path) + ".params.csv";
}

void write_export_csv(const ExportTable& table, const std::string& path) {
  {
    CsvFile f(path);
    std::string line;
    for (const auto& c : table.columns) line += (line.empty() ? "" : ",") + c.name;
    f.line(line);
    for (std::size_t i = 0; i < table.rows(); ++i) {
      line.clear();
      for (std::size_t k = 0; k < table.columns.size(); ++k) {
        if (k > 0) line += ',';
        line += csv_number(table.columns[k].values[i]);
      }
      f.line(line);
    }
    f.close();
  }
  const std::string params = params_csv_path(path);
  CsvFile f(params);
  f.line("name,value,std_error,unit");
  for (const auto& p : table.params) {
    f.line(fmt::format("{},{},{},{}", csv_text(p.name), csv_number(p.value), csv_number(p.std_error), csv_text(p.unit)));
  }
  f.close();
}

void write_export_mat(const ExportTable& table, const std::string& path) {
  const std::string header = "resolver-model export-data (MATLAB 5.0 MAT-file, matio)";
  errno = 0;
  std::unique_ptr<mat_t, int (*)(mat_t*)> mat(Mat_CreateVer(path.c_str(), header.c_str(), MAT_FT_MAT5), &Mat_Close);
  if (!mat) {
    if (errno != 0) throw std::system_error(errno, std::generic_category(), "cannot write " + path);
    throw IoError("cannot write " + path + ": matio failed");
  }
  std::vector<std::pair<std::string, Var>> samples, units, descriptions;
  for (const auto& c : table.columns) {
    samples.emplace_back(c.name, mat_column(c.values));
    units.emplace_back(c.name, mat_text(c.unit));
    descriptions.emplace_back(c.name, mat_text(c.description));
  }
  std::vector<std::string> names, param_units;
  std::vector<double> values, errors;
  for (const auto& p : table.params) {
    names.push_back(p.name);
    param_units.push_back(p.unit);
    values.push_back(p.value);
    errors.push_back(p.std_error);
  }
  std::vector<std::pair<std::string, Var>> params;
  params.emplace_back("name", mat_cells(names));
  params.emplace_back("value", mat_column(values));
  params.emplace_back("std_error", mat_column(errors));
  params.emplace_back("unit", mat_cells(param_units));
  std::vector<std::pair<std::string, Var>> info;
  for (const auto& [key, value] : table.info) {
    // Numbers as 1 x 1 doubles (info.p_r + 1 works in MATLAB), the rest as char rows.
    if (const double* number = std::get_if<double>(&value)) info.emplace_back(key, mat_column({*number}));
    else info.emplace_back(key, mat_text(std::get<std::string>(value)));
  }

  std::vector<Var> vars;
  vars.push_back(mat_struct("samples", std::move(samples)));
  vars.push_back(mat_struct("units", std::move(units)));
  vars.push_back(mat_struct("descriptions", std::move(descriptions)));
  vars.push_back(mat_struct("params", std::move(params)));
  vars.push_back(mat_struct("info", std::move(info)));
  for (const Var& v : vars) {
    if (Mat_VarWrite(mat.get(), v.get(), MAT_COMPRESSION_ZLIB) != 0) {
      throw IoError(fmt::format("cannot write {}: matio failed writing {}", path, v->name));
    }
  }
  if (Mat_Close(mat.release()) != 0) {
    throw IoError("cannot write " + path + ": closing failed");
  }
}

std::string export_data(const DiscoveryInput& input, std::span<const std::string> effects,
                        const DiscoveryOptions& options, std::string_view log_path, const std::string& csv_path,
                        const std::string& mat_path) {
  const PreparedLog log = prepare_log(input, options.prepare);
  const ModelFit fit = fit_prepared(log, effects, options);
  const ExportTable table = export_table(input, log, fit, log_path);
  const std::string what = fmt::format("{} samples x {} columns, {} parameters of {}", table.rows(),
                                       table.columns.size(), table.params.size(),
                                       std::get<std::string>(table.info[1].second));
  std::string o;
  if (!csv_path.empty()) {
    write_export_csv(table, csv_path);
    o += fmt::format("wrote {} ({}) and {} (the parameters)\n", csv_path, what, params_csv_path(csv_path));
  }
  if (!mat_path.empty()) {
    write_export_mat(table, mat_path);
    o += fmt::format("wrote {} ({}; structs samples, units, descriptions, params, info)\n", mat_path, what);
  }
  return o;
}

}  // namespace resolver
