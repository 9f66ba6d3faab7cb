// Per-sample signal chain of the daemon, as pure maths over one joined sample:
//
//   theta_rd ──► speed, Hwang integral estimator (alpha per revolution)
//            └─► compensation: theta_c = theta_rd + eps_hat(theta_rd)   (Hwang Fig. 5)
//   i_a,b,c  ──► Clarke ─► Park with theta_e from raw, compensated, reference angle
//                          └─► ripple at 1x, 2x, 6x theta_e per electrical revolution
//
// Angles follow daemon/core/angles.h: theta = p_r theta_m, theta_e = (p/p_r) theta.
// The motor electrical angle from the resolver uses the resolver angle unwrapped
// since the start of the stream, so for p not a multiple of p_r the electrical
// angle has an unknown constant (which resolver cycle the stream started in);
// ripple amplitudes do not depend on it.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "daemon/core/angles.h"
#include "daemon/core/sample.h"
#include "daemon/core/estimation/angle_error_fourier.h"
#include "daemon/core/estimation/hwang_integral.h"
#include "daemon/core/estimation/sincos_compensation.h"
#include "daemon/core/estimation/sincos_least_squares.h"
#include "daemon/core/estimation/current_spike_gate.h"
#include "daemon/core/estimation/revolution_ripple.h"
#include "daemon/core/estimation/speed_estimator.h"
#include "daemon/core/model/calibration_table.h"
#include "daemon/core/model/compensator.h"

namespace resolver {

/// The processor's input is the shared sample (daemon/core/sample.h).
using SampleInput = Sample;

/// Which estimator runs (docs/ARCHITECTURE.md §5).
enum class EstimatorMethod : std::uint8_t {
  /// The active model ([model] effects) fitted by the live model fit on the
  /// signals present (sin/cos and R/D angle against the reference when there is
  /// one, self-calibrated otherwise), compensated by inverting it (compensator.h).
  /// The default: the best estimator for the signals the log has.
  kModel,
  kHwangIntegral,      ///< R/D angle only, constant speed: alpha (Hwang 2009), the seed baseline
  kSinCosLeastSquares, ///< sin/cos envelopes: alpha, beta, offsets (+ harmonics with a reference)
  kFourierReference,   ///< position error vs reference angle, Fourier series (Hanselman III.A)
};
/// Where the compensation acts.
enum class CompensationDomain : std::uint8_t {
  kAngle,   ///< theta_c = theta_rd + eps_hat(theta_rd)   (Hwang Fig. 5)
  kSignal,  ///< correct sin/cos, then atan2               (sin/cos least squares only)
};
/// The method named as in the config ([estimator] method), or nullopt for an unknown name.
[[nodiscard]] std::optional<EstimatorMethod> estimator_from_name(std::string_view name);
[[nodiscard]] std::string_view estimator_name(EstimatorMethod method);
/// "model, hwang_integral, ...": every name estimator_from_name() accepts, the default first
/// (for messages and help, so no hand-kept list drifts from the code). Cannot fail.
[[nodiscard]] std::string estimator_names();

/// One parameter of the active model, named "effect.param" as in the catalog.
/// Everything estimate_t publishes.
struct ModelEstimate {
  std::string method;
  std::vector<ModelParameter> params;
  std::int64_t samples = 0;
  double revolutions = 0.0;
  bool converged = false;
};

struct ProcessorConfig {
  EstimatorMethod method = EstimatorMethod::kModel;
  CompensationDomain domain = CompensationDomain::kAngle;
  SinCosLsConfig sincos;
  AngleFourierConfig fourier;
  int p_r = 3;  ///< resolver pole pairs
  int p = 3;    ///< motor pole pairs
  HwangIntegralConfig hwang;
  bool compensate = true;
  /// Electrical revolutions coherently averaged for the ripple amplitudes.
  int ripple_revolutions = 8;
  bool operator==(const ProcessorConfig&) const = default;
};

struct RippleSet {
  RippleAmplitudes raw, comp, ref;
  bool raw_valid = false, comp_valid = false, ref_valid = false;
};

struct SampleOutput {
  bool has_angle = false;
  /// The rotor moves (hysteresis on the travel over the last 10 samples against the
  /// angle's sample noise: 6 sigma to start, 3 sigma to stop; motion.h's rule, streaming).
  bool moving = false;
  double theta_rd = 0.0;       ///< [rad] wrapped
  double theta_sincos = 0.0;   ///< [rad] wrapped; NaN without sin/cos
  double theta_comp = 0.0;     ///< [rad] wrapped
  double theta_ref = 0.0;      ///< [rad] resolver electrical reference, wrapped; NaN without reference
  double speed_mech = 0.0;     ///< [rad/s]
  double eps_hat = 0.0;        ///< [rad] compensation term added to theta_rd
  double eps_ref = 0.0;        ///< [rad] theta_ref - theta_rd wrapped to [-pi,pi); NaN without reference
  std::optional<HwangRevolution> revolution;  ///< set when this sample closed a resolver revolution
  bool estimate_updated = false;              ///< estimate() changed on this sample (once per revolution)

  bool has_dq = false;
  double electrical_freq_hz = 0.0;
  double i_d_raw = 0.0, i_q_raw = 0.0;
  double i_d_comp = 0.0, i_q_comp = 0.0;
  double i_d_ref = 0.0, i_q_ref = 0.0;  ///< NaN without reference
  /// Which ripple trackers closed an electrical revolution on this sample.
  bool ripple_raw_updated = false, ripple_comp_updated = false, ripple_ref_updated = false;
  [[nodiscard]] bool ripple_updated() const { return ripple_raw_updated || ripple_comp_updated || ripple_ref_updated; }
};

class SampleProcessor {
 public:
  explicit SampleProcessor(const ProcessorConfig& config);

  /// Processes one sample. Cannot fail; missing signals give NaN outputs.
  SampleOutput process(const SampleInput& in);

  /// Changes pole pairs (BENCH_INFO); restarts estimation, which depends on them.
  void set_pole_pairs(int p_r, int p);

  [[nodiscard]] const ProcessorConfig& config() const { return config_; }
  [[nodiscard]] const HwangIntegralEstimator& estimator() const { return estimator_; }
  /// The active method's current estimate, every parameter with its standard error.
  [[nodiscard]] ModelEstimate estimate() const;
  /// True once the compensation uses a converged (or seeded) estimate.
  [[nodiscard]] bool compensating() const;
  [[nodiscard]] const RippleSet& ripple() const { return ripple_; }
  /// Phase-current samples left out of the ripple as spikes (current_spike_gate.h).
  [[nodiscard]] std::int64_t current_spikes() const { return spike_gate_.rejected(); }
  /// Compensates with `model` from now on: method kModel's live window fit (also its
  /// estimate), or a persisted calibration at start or a reload's carried-over model,
  /// which an older method's own estimate replaces once it has one (estimator_models.h).
  /// `samples`, `revolutions`: what it was fitted on.
  void set_model(Model model, std::int64_t samples, double revolutions);
  /// resolverd --calibration: compensate with an exported table from now on
  /// (instead of the estimator's own result; the estimator still runs and publishes).
  void set_table(CalibrationTable table) { table_.emplace(std::move(table)); }
  /// The model compensating now (empty before the first fit or seed).
  [[nodiscard]] const Model& model() const { return compensator_.model(); }
  /// The active method's own estimate as a Model (kModel: the model set last; the
  /// older methods: their latest result, estimator_models.h; empty before one).
  [[nodiscard]] Model estimated_model() const;
  /// Hwang's integral runs beside every method, as the seed's baseline for reports.
  [[nodiscard]] const HwangIntegralEstimator& hwang() const { return estimator_; }

 private:
  // process(), step by step.
  void feed_estimator(const SampleInput& in, double theta_meas, SampleOutput& out);
  void count_revolution(SampleOutput& out);
  [[nodiscard]] bool update_motion_gate();
  void compensate(const SampleInput& in, double theta_meas, double omega, SampleOutput& out);
  void reference_angles(const SampleInput& in, double theta_meas, SampleOutput& out);
  void dq_and_ripple(const SampleInput& in, SampleOutput& out);
  /// Compensates with `model` from now on (when compensation is on).
  void adopt(Model model);
  /// Solves the sin/cos or Fourier fit at the end of a resolver revolution.
  void close_revolution(SampleOutput& out);

  ProcessorConfig config_;
  HwangIntegralEstimator estimator_;
  SinCosLeastSquares sincos_ls_;
  AngleErrorFourier fourier_;
  std::optional<SinCosFit> sincos_fit_;
  std::optional<AngleErrorFit> fourier_fit_;
  double rev_anchor_ = 0.0;  ///< [rad] unwrapped angle where the current revolution started
  std::int64_t revolutions_ = 0;
  bool rev_started_ = false;
  std::int64_t samples_ = 0;
  SpeedEstimator speed_;
  AngleUnwrapper rd_unwrap_;
  AngleUnwrapper ref_unwrap_;
  double ref_cont_ = 0.0;  ///< [rad, mechanical] the reference unwrapped at the current sample (NaN without)
  RevolutionRipple ripple_raw_, ripple_comp_, ripple_ref_;
  CurrentSpikeGate spike_gate_;
  // Motion gate (SampleOutput::moving).
  static constexpr std::size_t kTravelSpan = 10;
  double recent_[kTravelSpan + 1] = {};
  std::size_t recent_n_ = 0;
  double second_diff_ema_ = 0.0;  ///< [rad] running mean |second difference| of the angle
  bool moving_ = false;
  RippleSet ripple_;
  Compensator compensator_;
  std::optional<TableCompensator> table_;
  bool model_set_ = false;
  bool model_updated_ = false;   ///< a new model arrived: estimate_t on the next sample
  std::int64_t model_samples_ = 0;
  double model_revolutions_ = 0.0;
};

}  // namespace resolver
