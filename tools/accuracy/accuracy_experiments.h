// Accuracy of the estimators against known truth (issue "accuracy against the
// Cramer-Rao bound"). Every experiment simulates in memory with the bench
// simulator (tools/sim), runs the estimators of daemon/core/estimation on the
// samples the daemon would see, and summarises over seeds:
//
//   study            data                                     what is measured
//   ---------------  ---------------------------------------  -------------------------------------------
//   accuracy         alpha, beta, o_s, o_c + default chain,    bias, std of each estimate over seeds vs
//                    200 r/min, 1 s (10 resolver revolutions)   the CRLB (sin/cos) or the quantization LS
//                                                               floor (R/D angle); Hwang vs LS per log
//   convergence      alpha only + default chain, same length   revolutions of data until the estimate stays
//                                                               within 1 % of alpha
//   ripple           alpha only, 200 / 1000 r/min, 1 s fit +   2x i_d ripple with the raw and compensated
//                    2 s evaluation                             angles, against the noise floor
//
// Seeds: seed k sets the simulator's noise seed and a start angle drawn from it,
// so the R/D angle's quantization pattern differs between seeds as well (the
// converter sees noise-free envelopes; without a random start every seed would
// give the same R/D angle).
//
// Bounds (the "bound" column of the report):
//  - sin/cos least squares: crlb_sincos (reference, aligned) / crlb_sincos_blind
//    (conic) with the samples' effective noise sigma = sqrt(sigma_sc^2 + 1/12)
//    counts (Gaussian noise plus rounding to i16) and n = samples in the window.
//  - R/D-angle estimators (Fourier fit, Hwang): the R/D angle carries the
//    converter's quantization, uniform with sigma_q = LSB/sqrt(12). A least-squares
//    Fourier coefficient over n samples then has std sigma_q sqrt(2/n): alpha = 2 a_2
//    and beta = 2 b_2 have 2 sigma_q sqrt(2/n), o_c = a_1 and o_s = -b_1 have
//    sigma_q sqrt(2/n). This is the LS floor for that noise (it would be the CRLB
//    if the noise were Gaussian; uniform noise has no regular CRLB).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "tools/sim/bench_simulator.h"

namespace resolver::accuracy {

/// What the estimators see of one simulated sample, plus the truth.
struct Record {
  double t = 0.0;           ///< [s]
  double theta = 0.0;       ///< [rad] true resolver electrical angle (simulator truth)
  double theta_ref = 0.0;   ///< [rad] resolver electrical angle from the u32 reference encoder
  double s = 0.0, c = 0.0;  ///< [counts] sin/cos envelopes as transmitted (i16)
  double rd = 0.0;          ///< [rad] R/D angle as transmitted
  double i_a = 0.0, i_b = 0.0, i_c = 0.0;  ///< [A] phase currents as transmitted (1 mA/bit)
};

/// Runs the simulator to the end of its profile. Throws like BenchSimulator.
[[nodiscard]] std::vector<Record> simulate_records(const SimConfig& config);

/// `base` with the simulator seed and a start angle theta_m0 drawn from `seed`.
[[nodiscard]] SimConfig seeded(SimConfig base, std::uint64_t seed);

/// Effective per-channel sin/cos noise of the i16 samples [counts]: sqrt(sigma_sc^2 + 1/12).
[[nodiscard]] double effective_sincos_sigma(const SimConfig& config);
/// R/D quantization noise LSB/sqrt(12) [rad].
[[nodiscard]] double rd_quantization_sigma(const SimConfig& config);

/// Spread of one parameter over seeds.
struct ParamStats {
  std::string name;
  double truth = 0.0;
  double bias = 0.0;   ///< mean(estimate) - truth
  double std = 0.0;    ///< sample standard deviation over seeds
  double bound = 0.0;  ///< CRLB or LS floor (see the header); NaN when none
  double mean_reported_se = 0.0;  ///< mean of the estimator's own standard error (NaN if none)
  int count = 0;       ///< seeds with a result
};

struct EstimatorStats {
  std::string name;        ///< e.g. "sin/cos LS, reference"
  std::string bound_kind;  ///< "CRLB (reference)", "CRLB (blind)", "LS floor (R/D quantization)"
  bool signal_domain = false;  ///< works on the sin/cos envelopes (the 2x CRLB target applies)
  std::vector<ParamStats> params;
};

struct StudyOptions {
  int seeds = 50;
  double rpm = 200.0;      ///< [r/min] constant speed
  double seconds = 1.0;    ///< [s] window (10 resolver revolutions at 200 r/min, p_r = 3)
};

struct AccuracyStudy {
  SimConfig config;              ///< seed-0 configuration (truth, noise)
  std::int64_t samples = 0;      ///< samples per window
  double revolutions = 0.0;      ///< resolver electrical revolutions per window
  double sigma_sc_eff = 0.0;     ///< [counts]
  double sigma_q = 0.0;          ///< [rad]
  std::vector<EstimatorStats> estimators;
  /// Hwang alpha minus sin/cos LS (reference) alpha on the same log: mean and std over seeds.
  double hwang_minus_ls_mean = 0.0, hwang_minus_ls_std = 0.0;
  /// The same for the Fourier fit (reference) minus sin/cos LS (reference).
  double fourier_minus_ls_mean = 0.0, fourier_minus_ls_std = 0.0;
};

/// alpha, beta = 0.01, o_s = 0.005, o_c = -0.004 on the default simulator chain.
[[nodiscard]] AccuracyStudy run_accuracy_study(double alpha, const StudyOptions& options);

struct ConvergenceStats {
  std::string name;
  /// Per seed: resolver electrical revolutions of data after which every later
  /// estimate (checked every quarter revolution) is within 1 % of alpha;
  /// +infinity when the last estimate of the window is not.
  std::vector<double> revolutions;
  /// Per seed: the estimate at the end of the window (all of the log).
  std::vector<double> final_alpha;
  [[nodiscard]] double quantile(double q) const;  ///< over seeds; +inf if that many did not converge
  [[nodiscard]] double fraction_within(double revs) const;
  [[nodiscard]] double final_bias(double truth) const;  ///< mean(final_alpha) - truth
  [[nodiscard]] double final_std() const;               ///< std of final_alpha over seeds
};

struct ConvergenceStudy {
  double alpha = 0.0;
  double window_revolutions = 0.0;
  std::vector<ConvergenceStats> estimators;
};

/// alpha only on the default simulator chain.
[[nodiscard]] ConvergenceStudy run_convergence_study(double alpha, const StudyOptions& options);

struct RippleStudy {
  double rpm = 0.0;
  double alpha = 0.0;
  int seeds = 0;
  double eval_revolutions = 0.0;    ///< motor electrical revolutions coherently averaged
  double samples_per_revolution = 0.0;  ///< per motor electrical revolution
  // Mean over seeds of the 2x i_d ripple amplitude [A] with each angle:
  double raw = 0.0;      ///< R/D angle as is
  double hwang = 0.0;    ///< R/D + (alpha_hwang/2) sin 2theta (Hwang Fig. 5; what resolverd does)
  double fourier = 0.0;  ///< R/D + Fourier eps_hat (fitted against the reference)
  double sincos = 0.0;   ///< atan2 of the sin/cos corrected by the LS fit (reference)
  double ref = 0.0;      ///< reference encoder angle: the measured floor
  /// Expected amplitude of a pure-noise 2x bin [A] (Rayleigh mean; see accuracy_experiments.cpp)
  /// with the R/D angle's and with the sin/cos angle's noise.
  double floor_rd = 0.0, floor_sincos = 0.0;
};

/// 1 s to fit the estimators, then `eval_seconds` of compensated angles.
[[nodiscard]] RippleStudy run_ripple_study(double rpm, double alpha, int seeds, double eval_seconds = 2.0);

}  // namespace resolver::accuracy
