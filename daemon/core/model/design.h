// The columns of a fit and how one row evaluates against them.
//
// A design has nuisance columns (the operating point: a constant of a signal the
// true angle cannot give, the envelopes' amplitude, the mean dq current), the
// model's terms (effects with their fitted parameters at the current values: the
// linearisation point) and, for ranking, candidate terms (columns only, at their
// neutral values, contributing nothing to the prediction).
//
// Envelope effects (Effect::envelope_only) are evaluated together and exactly
// (envelope_spectrum.h): their prediction is the exact atan2/hypot of the modelled
// envelopes and their columns the exact derivatives at the current point, so a
// Gauss-Newton fit relinearised to convergence is the exact least-squares fit at
// any magnitude, cross terms between effects included.
//
// The frame shift [rad, resolver electrical] is where the sensor's zero sits in the
// frame of the fit's true angle (an unaligned reference's zero, or the self-
// calibration's): the windings' errors are functions of the sensor's own angle, so
// every basis turns by it (BasisTransform::shift), and the position errors carry it
// as a constant (-shift on rd and sa). It is the coordinate of the position error's
// nuisance constant: the fit moves it by that column's step (fit_design), so the
// parameters do not depend on the reference's zero.
//
// Parts (a pooled fit of several logs of one bench, FitRow::part): the sensor's
// parameters are shared, each part has its own nuisance columns and frame shift
// (each log's reference zero, envelope amplitude and operating point). Columns:
// part 0's nuisances, part 1's, ..., then the terms.
//
// Internal coordinates z (what Gauss-Newton moves): a linear parameter is its
// value; a nonlinear one with FitScale::kInverseSquare is 1/value^2 (0 = neutral);
// a polar pair is its Cartesian pair (effect.h). Linear parameters' Jacobian
// columns are the effects' signature columns; nonlinear ones are differentiated
// numerically through the whole prediction (they act on every other effect).
#pragma once

#include <Eigen/Dense>
#include <algorithm>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "daemon/core/effects/effect.h"
#include "daemon/core/model/envelope_spectrum.h"
#include "daemon/core/model/fit_row.h"
#include "daemon/core/model/loop_correction.h"
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
  /// A candidate that frees a parameter the model's term of the same effect holds fixed
  /// (a loop's zeta): its values are that term's, and moved it stands in for that term
  /// (Design::add_candidate).
  bool replaces_model_term = false;
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

  /// Adds a candidate term (columns at the effect's neutral values). Of an effect whose
  /// contribution is not linear in its values (a tracking loop) that the model has, the
  /// candidate starts at the model's term's values and, moved, stands in for it: its
  /// columns are the derivatives at the model's point (at neutral values a loop's zeta
  /// column is that of an ideal converter: zero).
  void add_candidate(const ModelTerm& term);

  [[nodiscard]] int columns() const { return columns_; }
  /// The nuisance kinds of one part (each part has its own columns of them).
  [[nodiscard]] const std::vector<Nuisance>& nuisances() const { return nuisances_; }
  /// Pooled parts (>= 1); setting it keeps part 0's frame shift for every new part.
  [[nodiscard]] int parts() const { return static_cast<int>(frame_shifts_.size()); }
  void set_parts(int parts);
  /// Nuisance columns of every part: the first nuisance_columns() columns.
  [[nodiscard]] int nuisance_columns() const { return static_cast<int>(nuisances_.size()) * parts(); }
  /// Column of nuisance kind index `j` of part `part`.
  [[nodiscard]] int nuisance_column(int part, std::size_t j) const {
    return part * static_cast<int>(nuisances_.size()) + static_cast<int>(j);
  }
  [[nodiscard]] const std::vector<DesignTerm>& terms() const { return terms_; }
  /// Mutable terms (the cached envelope series is recomputed on next use).
  [[nodiscard]] std::vector<DesignTerm>& terms() {
    envelope_.valid = false;
    return terms_;
  }
  /// [rad, resolver electrical] the sensor's zero in the fit's frame (header comment).
  [[nodiscard]] double frame_shift(int part = 0) const { return frame_shifts_[static_cast<std::size_t>(part)]; }
  /// Sets one part's shift.
  void set_frame_shift(int part, double shift) { frame_shifts_[static_cast<std::size_t>(part)] = shift; }
  /// Sets every part's shift.
  void set_frame_shift(double shift) { std::fill(frame_shifts_.begin(), frame_shifts_.end(), shift); }
  [[nodiscard]] const std::vector<double>& frame_shifts() const { return frame_shifts_; }
  /// "nuisance.sr_gain", "amplitude_imbalance.alpha", "eccentricity.e_x" ... per column.
  [[nodiscard]] std::vector<std::string> column_names() const;
  /// First column of term i.
  [[nodiscard]] int term_column(std::size_t i) const { return term_first_[i]; }
  /// True when a model (not candidate) parameter is nonlinear or a model term
  /// shapes the basis (Gauss-Newton then iterates).
  [[nodiscard]] bool nonlinear() const;

  /// The internal coordinates of the fitted parameters (nuisance entries 0).
  [[nodiscard]] Eigen::VectorXd z() const;
  /// Moves the model's parameters by dz (internal coordinates; nuisance and
  /// candidate entries ignored). Values are clamped to their ranges.
  void step(const Eigen::VectorXd& dz);
  /// True when column `col`'s parameter sits at a bound of its range and `dz` would
  /// push it past (a converter that is ideal: 1 / omega_n^2 = 0 asked to go below):
  /// the fit then holds it at the bound instead of taking a step step() would clamp.
  [[nodiscard]] bool pushed_past_bound(int col, double dz) const;
  /// Moves one column's coordinate only (numeric derivatives).
  [[nodiscard]] std::vector<double> values_with(std::size_t term, int column_in_term, double dz) const;

  /// How many of `rows` (fitted, with an R/D angle) take the loop correction at a speed
  /// where its harmonic balance did not converge (loop_correction.h: the envelopes'
  /// radius swings too far for the loop's steady state); 0 without a loop.
  [[nodiscard]] std::int64_t loop_balance_unconverged(std::span<const FitRow> rows) const;

  /// Evaluates one row: the prediction of every signal (model terms) and the
  /// Jacobian rows of every column. `basis` is scratch.
  void evaluate(const FitRow& row, AngleBasis& basis, SignalValues& prediction, RowJacobian& jac) const {
    evaluate_row(row.sig, row.part, basis, prediction, jac);
  }
  /// The same for rows[i], with the earlier rows as the angle's history (a delay
  /// reads theta(t - d) from them: exact across speed steps).
  void evaluate(std::span<const FitRow> rows, std::size_t i, AngleBasis& basis, SignalValues& prediction,
                RowJacobian& jac) const;
  /// The prediction only (compensation, residual series).
  [[nodiscard]] SignalValues predict(const FitRow& row, AngleBasis& basis) const;
  [[nodiscard]] SignalValues predict(std::span<const FitRow> rows, std::size_t i, AngleBasis& basis) const;

 private:
  [[nodiscard]] BasisTransform transform(const SignatureRow& row, int part, std::size_t extra_term,
                                         const std::vector<double>* extra_values) const;
  /// `tr`: the basis transform to use instead of the terms' (a shift moved: evaluate_row).
  [[nodiscard]] SignalValues predict_with(const SignatureRow& row, int part, AngleBasis& basis, std::size_t override_term,
                                          const std::vector<double>* override_values,
                                          const BasisTransform* tr = nullptr) const;
  /// d(prediction)/d(shift) of the model at a row (the seen angle's shift, BasisTransform):
  /// numerically, one prediction with the shift moved.
  [[nodiscard]] SignalValues shift_slope(const SignatureRow& row, int part, const SignalValues& prediction) const;
  void rebuild();
  /// Whether model term `i` is left out of a prediction with `override_term` moved: that
  /// candidate replaces_model_term and is of i's effect.
  [[nodiscard]] bool stood_in_for(std::size_t i, std::size_t override_term,
                                  const std::vector<double>* override_values) const;
  /// The envelope terms' joint series and every envelope column's derivative series
  /// at the current values (computed on first use after a change).
  struct EnvelopeCache {
    bool valid = false;
    std::vector<std::size_t> model_terms;  ///< indices of non-candidate envelope terms
    EnvelopeSeries series;                 ///< the model's e(phi), r(phi)
    std::vector<std::vector<EnvelopeSeries>> columns;  ///< [term][k]: d/d(param k), empty for other terms
    /// The series' correction under each loop the rows were evaluated with (the model's,
    /// and its numeric derivatives' moved ones), nodes filled as rows need them.
    std::vector<LoopCorrection> loops;
  };
  const EnvelopeCache& envelope() const;
  /// The model's envelope series' loop correction under `loop` (loop_correction.h).
  [[nodiscard]] const LoopCorrection& loop_correction(const TrackingLoopParams& loop) const;
  [[nodiscard]] std::vector<EnvelopeMember> envelope_members(std::size_t override_term,
                                                             const std::vector<double>* override_values,
                                                             std::size_t with_candidate) const;
  void evaluate_row(const SignatureRow& row, int part, AngleBasis& basis, SignalValues& prediction,
                    RowJacobian& jac) const;

  std::vector<Nuisance> nuisances_;
  std::vector<DesignTerm> terms_;
  std::vector<int> term_first_;
  int columns_ = 0;
  std::vector<double> frame_shifts_ = std::vector<double>(1, 0.0);  ///< per part
  mutable std::vector<SignalValues> scratch_;
  /// The basis of a numeric derivative's moved prediction: a member, not a local, so its
  /// series keep their storage from row to row (an allocation per row was a tenth of a fit).
  mutable AngleBasis shifted_;
  mutable EnvelopeCache envelope_;
};

/// Internal coordinate of parameter `p` at `value` and back (design.h header).
[[nodiscard]] double to_internal(const ParamInfo& p, double value);
[[nodiscard]] double from_internal(const ParamInfo& p, double z);

}  // namespace resolver
