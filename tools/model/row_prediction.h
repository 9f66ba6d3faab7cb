// The fitted model's prediction of every signal at a row of a prepared log, as the
// fit saw it: the model's effects at the fitted values (Model::predict) plus the
// constants the fit estimates beside them (the nuisance columns of design.h: an
// angle constant without a reference, the envelopes' gain, the dq operating point).
//
// ModelFit does not carry those constants. Each is a constant column, so at the least
// squares solution its normal equation says the residual sums to zero over the fitted
// rows of its signal: the constant is the mean of (measured - effects) there. One pass
// over the rows finds them. With them, the rms of measured - prediction over the fitted
// rows is the fit's residual rms of each signal (tests/model/test_export_data.py).
#pragma once

#include "daemon/core/discovery/prepare.h"
#include "daemon/core/model/model.h"

namespace resolver {

class RowPredictor {
 public:
  /// `model` fitted on `log` (ModelFit::model); both must outlive the predictor.
  RowPredictor(const PreparedLog& log, const Model& model);

  /// Effects + constants at `row`.
  [[nodiscard]] SignalValues operator()(const FitRow& row) const;
  /// The effects alone (what compensation subtracts).
  [[nodiscard]] SignalValues effects(const FitRow& row) const { return model_.predict_in_log_frame(row.sig); }
  /// The constants per signal (0 where the fit has none).
  [[nodiscard]] const SignalValues& constants() const { return constants_; }

 private:
  const Model& model_;
  SignalValues constants_;
};

}  // namespace resolver
