// One Model, from fit to compensation to firmware export: the active effects
// (ModelSpec), every parameter's value and the covariance of the fitted ones.
// The same object is what resolver-model fits offline, what resolverd's live fit
// estimates and publishes (estimate_t, model_fit_t), what the compensation
// inverts (compensator.h), what the calibration store persists and what
// `resolver-model export` tabulates for a drive.
#pragma once

#include <Eigen/Dense>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "daemon/core/effects/signature.h"
#include "daemon/core/model/custom_effect.h"
#include "daemon/core/model/design.h"
#include "daemon/core/model/model_spec.h"
#include "daemon/core/model/parameter.h"

namespace resolver {

class Model {
 public:
  Model() = default;
  /// Every parameter at its neutral value. p_r, p >= 1.
  Model(ModelSpec spec, int p_r, int p);

  [[nodiscard]] const ModelSpec& spec() const { return spec_; }
  [[nodiscard]] int p_r() const { return p_r_; }
  [[nodiscard]] int p() const { return p_; }
  /// Per term, every parameter of its effect (fitted ones and the rest at neutral).
  [[nodiscard]] const std::vector<std::vector<double>>& values() const { return values_; }
  /// Sets a fitted parameter by name ("effect.param"). Throws std::invalid_argument
  /// when the model has no such fitted parameter.
  void set(std::string_view name, double value, double std_error = 0.0);
  /// Standard errors of the fitted parameters in parameters() order (NaN = unknown).
  void set_standard_errors(std::vector<double> se) { std_errors_ = std::move(se); }

  /// The fitted parameters, in term order, with their standard errors.
  [[nodiscard]] std::vector<ModelParameter> parameters() const;
  /// A design of this model at its values with `nuisances` (for fitting it).
  [[nodiscard]] Design design(std::vector<Nuisance> nuisances) const;
  /// Takes the model terms' values from a fitted design (same spec).
  void take_values(const Design& design);

  /// The model's prediction of every signal at a row of the sensor's own angles
  /// (compensation, the exported table).
  [[nodiscard]] SignalValues predict(const SignatureRow& row) const;
  /// The same at a row of the fitted log's true angles (its reference's frame:
  /// the sensor's zero sits at frame_shift() there; design.h).
  [[nodiscard]] SignalValues predict_in_log_frame(const SignatureRow& row) const;
  /// [rad, resolver electrical] the sensor's zero in the fitted log's frame (of the
  /// first log of a pooled fit: each log has its own, frame_shifts()).
  [[nodiscard]] double frame_shift() const { return frame_shifts_.front(); }
  [[nodiscard]] const std::vector<double>& frame_shifts() const { return frame_shifts_; }
  /// True when some term changes the R/D or sin/cos angle (compensation has work to do).
  [[nodiscard]] bool has_angle_terms() const;
  [[nodiscard]] bool empty() const { return spec_.terms.empty(); }
  /// Keeps the custom effects the model's terms point into alive as long as the model.
  void keep(std::shared_ptr<const CustomEffects> customs) { customs_ = std::move(customs); }

 private:
  [[nodiscard]] SignalValues predict_with_shift(const SignatureRow& row, double shift) const;

  ModelSpec spec_;
  int p_r_ = 1, p_ = 1;
  std::vector<std::vector<double>> values_;
  std::vector<double> std_errors_;
  std::vector<double> frame_shifts_ = std::vector<double>(1, 0.0);  ///< per pooled log (design.h "Parts")
  std::shared_ptr<const CustomEffects> customs_;
  mutable Design scratch_;
  mutable bool scratch_valid_ = false;
  /// The basis of the last predicted row, kept so that its series' buffers are not
  /// allocated again for every sample the compensator corrects (a third of a replay's
  /// compensation time was malloc and free).
  mutable AngleBasis basis_;
};

}  // namespace resolver
