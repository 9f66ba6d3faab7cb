// The columns of a fit and how one row evaluates against them.
//
// A design has nuisance columns (the operating point: a constant of a signal the
// true angle cannot give, the envelopes' amplitude, the mean dq current), the
// model's terms (effects with their fitted parameters at the current values: the
// linearisation point) and, for ranking, candidate terms (columns only, at their
// neutral values, contributing nothing to the prediction).
//
// Internal coordinates z (what Gauss-Newton moves): a linear parameter is its
// value; a nonlinear one with FitScale::kInverseSquare is 1/value^2 (0 = neutral);
// a polar pair is its Cartesian pair (effect.h). Linear parameters' Jacobian
// columns are the effects' signature columns; nonlinear ones are differentiated
// numerically through the whole prediction (they act on every other effect).
#pragma once

#include <Eigen/Dense>
#include <string>
#include <vector>

#include "daemon/core/effects/effect.h"
#include "daemon/core/model/fit_row.h"
#include "daemon/core/model/model_spec.h"

namespace resolver {

enum class Nuisance : std::uint8_t {
  kRdConstant,  ///< rd: a constant (no reference: the smoothed angle has no zero)
  kSaConstant,  ///< sa: a constant (no reference)
  kScGain,      ///< sr: the envelopes' amplitude
  kIdConstant,  ///< d: the operating point
  kIqConstant,  ///< q: the operating point
};
[[nodiscard]] std::string_view nuisance_name(Nuisance n);

struct DesignTerm {
  const Effect* effect = nullptr;
  std::vector<int> params;     ///< fitted parameter indices (ascending)
  std::vector<double> values;  ///< every parameter's value (the linearisation point)
  bool candidate = false;      ///< columns only: contributes nothing to the prediction
};

/// The five signals' Jacobian rows of one sample (length = columns).
struct RowJacobian {
  Eigen::VectorXd rd, sa, sr, d, q;
  void resize(int k);
  void set_zero();
};

class Design {
 public:
  Design() = default;
  /// `spec` at `values` (one vector per term, every parameter; empty = neutral).
  Design(const ModelSpec& spec, const std::vector<std::vector<double>>& values, std::vector<Nuisance> nuisances);

  /// Adds a candidate term (columns at the effect's neutral values).
  void add_candidate(const ModelTerm& term);

  [[nodiscard]] int columns() const { return columns_; }
  [[nodiscard]] const std::vector<Nuisance>& nuisances() const { return nuisances_; }
  [[nodiscard]] const std::vector<DesignTerm>& terms() const { return terms_; }
  [[nodiscard]] std::vector<DesignTerm>& terms() { return terms_; }
  /// "nuisance.sr_gain", "amplitude_imbalance.alpha", "eccentricity.e_x" ... per column.
  [[nodiscard]] std::vector<std::string> column_names() const;
  /// First column of term i.
  [[nodiscard]] int term_column(std::size_t i) const { return term_first_[i]; }
  /// True when a model (not candidate) parameter is nonlinear.
  [[nodiscard]] bool nonlinear() const;

  /// The internal coordinates of the fitted parameters (nuisance entries 0).
  [[nodiscard]] Eigen::VectorXd z() const;
  /// Moves the model's parameters by dz (internal coordinates; nuisance and
  /// candidate entries ignored). Values are clamped to their ranges.
  void step(const Eigen::VectorXd& dz);
  /// Moves one column's coordinate only (numeric derivatives).
  [[nodiscard]] std::vector<double> values_with(std::size_t term, int column_in_term, double dz) const;

  /// Evaluates one row: the prediction of every signal (model terms) and the
  /// Jacobian rows of every column. `basis` is scratch.
  void evaluate(const FitRow& row, AngleBasis& basis, SignalValues& prediction, RowJacobian& jac) const;
  /// The prediction only (compensation, residual series).
  [[nodiscard]] SignalValues predict(const FitRow& row, AngleBasis& basis) const;

 private:
  [[nodiscard]] BasisTransform transform(std::size_t extra_term, const std::vector<double>* extra_values) const;
  [[nodiscard]] SignalValues predict_with(const SignatureRow& row, AngleBasis& basis, std::size_t override_term,
                                          const std::vector<double>* override_values) const;
  void rebuild();

  std::vector<Nuisance> nuisances_;
  std::vector<DesignTerm> terms_;
  std::vector<int> term_first_;
  int columns_ = 0;
  mutable std::vector<SignalValues> scratch_;
};

/// Internal coordinate of parameter `p` at `value` and back (design.h header).
[[nodiscard]] double to_internal(const ParamInfo& p, double value);
[[nodiscard]] double from_internal(const ParamInfo& p, double z);

}  // namespace resolver
