#include "tools/accuracy/accuracy_experiments.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>
#include <random>

#include "daemon/core/angles.h"
#include "daemon/core/effects/quantization.h"
#include "daemon/core/estimation/angle_error_fourier.h"
#include "daemon/core/estimation/cramer_rao.h"
#include "daemon/core/estimation/dq_transform.h"
#include "daemon/core/estimation/hwang_integral.h"
#include "daemon/core/estimation/revolution_ripple.h"
#include "daemon/core/estimation/sincos_compensation.h"
#include "daemon/core/estimation/sincos_least_squares.h"

namespace resolver::accuracy {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kRefCountsPerTurn = 4294967296.0;  // docs/ARCHITECTURE.md §4: 2^32 counts per mechanical turn
constexpr double kAmpsPerCurrentBit = 1e-3;         // docs/ARCHITECTURE.md §4: PHASE_CURRENTS at 1 mA/bit
constexpr double kConvergenceTolerance = 0.01;      // 1 % of alpha (the criterion)
// Truth of the accuracy study besides alpha: percent-level, the catalog's examples.
constexpr double kBeta = 0.01;     // [rad]
constexpr double kOs = 0.005;      // [fraction of A]
constexpr double kOc = -0.004;     // [fraction of A]

double mean_of(const std::vector<double>& v) {
  double s = 0.0;
  for (double x : v) s += x;
  return v.empty() ? kNaN : s / static_cast<double>(v.size());
}

double std_of(const std::vector<double>& v) {
  if (v.size() < 2) return kNaN;
  const double m = mean_of(v);
  double s = 0.0;
  for (double x : v) s += (x - m) * (x - m);
  return std::sqrt(s / static_cast<double>(v.size() - 1));
}

/// One parameter's values over seeds, with the estimator's own standard errors.
struct Samples {
  std::vector<double> value;
  std::vector<double> se;
  void add(const Estimate& e) {
    value.push_back(e.value);
    se.push_back(e.std_error);
  }
};

ParamStats summarise(std::string name, double truth, const Samples& s, double bound) {
  ParamStats p;
  p.name = std::move(name);
  p.truth = truth;
  p.bias = mean_of(s.value) - truth;
  p.std = std_of(s.value);
  p.bound = bound;
  p.mean_reported_se = mean_of(s.se);
  p.count = static_cast<int>(s.value.size());
  return p;
}

SimConfig base_config(double rpm, double seconds, double alpha) {
  SimConfig cfg;
  cfg.profile = {{seconds, rpm, rpm}};
  cfg.chain.set("amplitude_imbalance", "alpha", alpha);
  return cfg;
}

double samples_per_resolver_revolution(const SimConfig& cfg, double rpm) {
  return cfg.sample_rate_hz / (rpm / 60.0 * cfg.p_r);
}

SinCosLsConfig ls_config() {
  SinCosLsConfig lc;
  lc.fit_reference_offset = false;  // the simulator's encoder is aligned with the resolver (theta_0 = 0)
  return lc;
}

}  // namespace

std::vector<Record> simulate_records(const SimConfig& config) {
  BenchSimulator sim(config);
  std::vector<Record> out;
  out.reserve(sim.total_samples());
  SimSample s{};
  while (sim.next(s)) {
    Record r;
    r.t = static_cast<double>(s.index) / config.sample_rate_hz;
    r.theta = s.theta;
    r.theta_ref = wrap_2pi(config.p_r * (static_cast<double>(s.ref_counts) / kRefCountsPerTurn) * kTwoPi);
    r.s = s.sin_counts;
    r.c = s.cos_counts;
    r.rd = s.rd_angle;
    r.i_a = s.i_a_ma * kAmpsPerCurrentBit;
    r.i_b = s.i_b_ma * kAmpsPerCurrentBit;
    r.i_c = s.i_c_ma * kAmpsPerCurrentBit;
    out.push_back(r);
  }
  return out;
}

SimConfig seeded(SimConfig base, std::uint64_t seed) {
  base.seed = seed;
  // A separate stream for the start angle (the simulator's engine is seeded with `seed`).
  NoiseEngine engine(seed ^ 0x5DEECE66DULL);
  std::uniform_real_distribution<double> angle(0.0, kTwoPi);
  base.theta_m0 = angle(engine);
  return base;
}

double effective_sincos_sigma(const SimConfig& config) {
  const double g = config.chain.get("noise", "sigma_sc");
  return std::sqrt(g * g + 1.0 / 12.0);  // Gaussian + rounding to integer counts (uniform, 1/12 count^2)
}

double rd_quantization_sigma(const SimConfig& config) {
  return quantization_lsb(config.rd_bits) / std::sqrt(12.0);
}

// ---------------------------------------------------------------------------
// Accuracy: bias and spread over seeds.

AccuracyStudy run_accuracy_study(double alpha, const StudyOptions& options) {
  SimConfig base = base_config(options.rpm, options.seconds, alpha);
  base.chain.set("quadrature", "beta", kBeta);
  base.chain.set("offsets", "o_s", kOs);
  base.chain.set("offsets", "o_c", kOc);

  // [estimator][alpha, beta, o_s, o_c]
  Samples ref[4], conic[4], fourier[4], hwang;
  std::vector<double> hwang_minus_ls, fourier_minus_ls;
  std::int64_t samples = 0;
  for (int k = 0; k < options.seeds; ++k) {
    const SimConfig cfg = seeded(base, static_cast<std::uint64_t>(k) + 1);
    const std::vector<Record> recs = simulate_records(cfg);
    samples = static_cast<std::int64_t>(recs.size());
    SinCosLeastSquares ls(ls_config());
    AngleErrorFourier af(AngleFourierConfig{});
    HwangIntegralEstimator hw(HwangIntegralConfig{});
    for (const Record& r : recs) {
      ls.add(r.s, r.c, r.theta_ref);
      af.add(r.theta_ref, r.rd);
      (void)hw.update(r.t, r.rd);
    }
    const std::optional<SinCosFit> fr = ls.solve_reference();
    const std::optional<SinCosFit> fc = ls.solve_conic();
    const std::optional<AngleErrorFit> ff = af.solve();
    if (fr) {
      ref[0].add(fr->alpha), ref[1].add(fr->beta), ref[2].add(fr->o_s), ref[3].add(fr->o_c);
    }
    if (fc) {
      conic[0].add(fc->alpha), conic[1].add(fc->beta), conic[2].add(fc->o_s), conic[3].add(fc->o_c);
    }
    if (ff) {
      fourier[0].add(ff->alpha), fourier[1].add(ff->beta), fourier[2].add(ff->o_s), fourier[3].add(ff->o_c);
    }
    if (hw.revolutions() > 0) hwang.add({hw.alpha(), hw.alpha_stderr()});
    if (fr && hw.revolutions() > 0) hwang_minus_ls.push_back(hw.alpha() - fr->alpha.value);
    if (fr && ff) fourier_minus_ls.push_back(ff->alpha.value - fr->alpha.value);
  }

  AccuracyStudy out;
  out.config = seeded(base, 1);
  out.samples = samples;
  out.revolutions = static_cast<double>(samples) / samples_per_resolver_revolution(base, options.rpm);
  out.sigma_sc_eff = effective_sincos_sigma(base);
  out.sigma_q = rd_quantization_sigma(base);
  const double truth[4] = {alpha, kBeta, kOs, kOc};
  const char* names[4] = {"alpha", "beta [rad]", "o_s", "o_c"};

  const CramerRao b_ref = crlb_sincos(base.amplitude_counts, out.sigma_sc_eff, samples);
  const CramerRao b_blind = crlb_sincos_blind(base.amplitude_counts, out.sigma_sc_eff, samples);
  // LS floor of a Fourier coefficient of eps with quantization noise (header).
  const double coef = out.sigma_q * std::sqrt(2.0 / static_cast<double>(samples));
  const double floor_rd[4] = {2.0 * coef, 2.0 * coef, coef, coef};

  EstimatorStats e_hwang{"Hwang integral (R/D angle)", "LS floor (R/D quantization)", false, {}};
  e_hwang.params.push_back(summarise(names[0], alpha, hwang, floor_rd[0]));
  EstimatorStats e_ref{"sin/cos LS, reference", "CRLB known angle", true, {}};
  EstimatorStats e_conic{"sin/cos LS, conic (no reference)", "CRLB blind", true, {}};
  EstimatorStats e_fourier{"Fourier fit of eps vs reference (R/D angle)", "LS floor (R/D quantization)", false, {}};
  const double bound_ref[4] = {b_ref.alpha, b_ref.beta, b_ref.o_s, b_ref.o_c};
  const double bound_blind[4] = {b_blind.alpha, b_blind.beta, b_blind.o_s, b_blind.o_c};
  for (int i = 0; i < 4; ++i) {
    e_ref.params.push_back(summarise(names[i], truth[i], ref[i], bound_ref[i]));
    e_conic.params.push_back(summarise(names[i], truth[i], conic[i], bound_blind[i]));
    e_fourier.params.push_back(summarise(names[i], truth[i], fourier[i], floor_rd[i]));
  }
  out.estimators = {e_hwang, e_ref, e_conic, e_fourier};
  out.hwang_minus_ls_mean = mean_of(hwang_minus_ls);
  out.hwang_minus_ls_std = std_of(hwang_minus_ls);
  out.fourier_minus_ls_mean = mean_of(fourier_minus_ls);
  out.fourier_minus_ls_std = std_of(fourier_minus_ls);
  return out;
}

// ---------------------------------------------------------------------------
// Convergence: revolutions of data until the alpha estimate stays within 1 %.

double ConvergenceStats::quantile(double q) const {
  if (revolutions.empty()) return kNaN;
  std::vector<double> v = revolutions;
  std::sort(v.begin(), v.end());
  const auto idx = static_cast<std::size_t>(std::ceil(q * static_cast<double>(v.size())) - 1.0);
  return v[std::min(idx, v.size() - 1)];
}

double ConvergenceStats::final_bias(double truth) const { return mean_of(final_alpha) - truth; }

double ConvergenceStats::final_std() const { return std_of(final_alpha); }

double ConvergenceStats::fraction_within(double revs) const {
  if (revolutions.empty()) return kNaN;
  const auto n = std::count_if(revolutions.begin(), revolutions.end(), [&](double r) { return r <= revs + 1e-9; });
  return static_cast<double>(n) / static_cast<double>(revolutions.size());
}

ConvergenceStudy run_convergence_study(double alpha, const StudyOptions& options) {
  const SimConfig base = base_config(options.rpm, options.seconds, alpha);
  const double per_rev = samples_per_resolver_revolution(base, options.rpm);
  const auto step = static_cast<std::size_t>(std::max(1.0, std::round(per_rev / 4.0)));  // quarter revolution
  constexpr int kEstimators = 4;
  ConvergenceStudy out;
  out.alpha = alpha;
  out.estimators = {{"Hwang integral (R/D angle)", {}, {}},
                    {"sin/cos LS, reference", {}, {}},
                    {"sin/cos LS, conic (no reference)", {}, {}},
                    {"Fourier fit of eps vs reference (R/D angle)", {}, {}}};
  for (int k = 0; k < options.seeds; ++k) {
    const std::vector<Record> recs = simulate_records(seeded(base, static_cast<std::uint64_t>(k) + 1));
    out.window_revolutions = static_cast<double>(recs.size()) / per_rev;
    SinCosLeastSquares ls(ls_config());
    AngleErrorFourier af(AngleFourierConfig{});
    HwangIntegralEstimator hw(HwangIntegralConfig{});
    // Latest checkpoint (in samples) at which each estimator was outside 1 %, or had no estimate.
    std::size_t last_bad[kEstimators] = {0, 0, 0, 0};
    double last_value[kEstimators] = {kNaN, kNaN, kNaN, kNaN};
    const auto check = [&](int e, std::optional<double> a, std::size_t n) {
      last_value[e] = a ? *a : kNaN;
      if (!a || !(std::abs(*a - alpha) <= kConvergenceTolerance * std::abs(alpha))) last_bad[e] = n;
    };
    for (std::size_t i = 0; i < recs.size(); ++i) {
      const Record& r = recs[i];
      ls.add(r.s, r.c, r.theta_ref);
      af.add(r.theta_ref, r.rd);
      (void)hw.update(r.t, r.rd);
      const std::size_t n = i + 1;
      if (n % step != 0 && n != recs.size()) continue;
      check(0, hw.revolutions() > 0 ? std::optional<double>(hw.alpha()) : std::nullopt, n);
      const auto fr = ls.solve_reference();
      check(1, fr ? std::optional<double>(fr->alpha.value) : std::nullopt, n);
      const auto fc = ls.solve_conic();
      check(2, fc ? std::optional<double>(fc->alpha.value) : std::nullopt, n);
      const auto ff = af.solve();
      check(3, ff ? std::optional<double>(ff->alpha.value) : std::nullopt, n);
    }
    for (int e = 0; e < kEstimators; ++e) {
      const bool never = last_bad[e] == recs.size();
      // Converged at the checkpoint after the last bad one: step samples later (or at once if none was bad).
      const double n_ok = last_bad[e] == 0 ? static_cast<double>(step)
                                           : static_cast<double>(std::min(last_bad[e] + step, recs.size()));
      ConvergenceStats& st = out.estimators[static_cast<std::size_t>(e)];
      st.revolutions.push_back(never ? kInf : n_ok / per_rev);
      if (!std::isnan(last_value[e])) st.final_alpha.push_back(last_value[e]);
    }
  }
  return out;
}

// ---------------------------------------------------------------------------
// dq ripple at 2x theta_e: raw vs compensated angle.
//
// Noise floor of the 2x bin. RevolutionRipple's coefficient of a revolution of N
// samples is c = (2/N) sum x_i exp(-2j theta_e,i); for white noise of variance
// sigma_d^2 in i_d, E|c|^2 = 4 sigma_d^2 / N, i.e. real and imaginary parts each
// of variance 2 sigma_d^2 / N; the coherent mean of K revolutions divides that by
// K, and its modulus is Rayleigh-distributed with mean sigma_d sqrt(pi / (N K)).
// i_d's noise: Clarke (amplitude invariant) gives i_alpha = i_a (variance
// sigma_i^2) and i_beta = (i_b - i_c)/sqrt(3) (variance 2/3 sigma_i^2), so
// i_d = i_alpha cos + i_beta sin has variance sigma_i^2 (1/2 + 1/3) = 5/6 sigma_i^2
// on average over the revolution, with sigma_i^2 = sigma_gauss^2 + (1 mA)^2/12 (the
// 1 mA/bit rounding). An angle error delta (resolver electrical) moves i_d by
// I_q (p/p_r) delta: variance I_q^2 (p/p_r)^2 sigma_angle^2, sigma_angle = LSB/sqrt(12)
// for the R/D angle, sigma_sc/A for the angle from the sin/cos samples.

namespace {

double ripple_floor(const SimConfig& cfg, double sigma_angle, double total_samples) {
  const double sigma_i = cfg.chain.get("noise", "sigma_i");  // [A]
  const double si2 = sigma_i * sigma_i + kAmpsPerCurrentBit * kAmpsPerCurrentBit / 12.0;
  const double ratio = static_cast<double>(cfg.p) / cfg.p_r;
  const double iq = std::hypot(cfg.i_d_cmd, cfg.i_q_cmd);
  const double var_d = 5.0 / 6.0 * si2 + iq * iq * ratio * ratio * sigma_angle * sigma_angle;
  return std::sqrt(var_d * std::numbers::pi / total_samples);
}

/// 2x i_d ripple [A] of the samples with the angle given per record, coherently over all revolutions.
class RippleProbe {
 public:
  explicit RippleProbe(double ratio) : ratio_(ratio), ripple_(1 << 20) {}
  void add(double theta_resolver_wrapped, const Record& r) {
    const double theta_e = ratio_ * unwrap_.update(theta_resolver_wrapped);
    const ClarkeTransform ab(r.i_a, r.i_b, r.i_c);
    const ParkTransform dq(ab.alpha, ab.beta, theta_e);
    (void)ripple_.update(theta_e, dq.d, dq.q);
  }
  [[nodiscard]] double amplitude_2x() const { return ripple_.valid() ? ripple_.last().d[1] : kNaN; }
  [[nodiscard]] std::int64_t revolutions() const { return ripple_.revolutions(); }

 private:
  double ratio_;
  AngleUnwrapper unwrap_;
  RevolutionRipple ripple_;
};

}  // namespace

RippleStudy run_ripple_study(double rpm, double alpha, int seeds, double eval_seconds) {
  constexpr double kFitSeconds = 1.0;
  const SimConfig base = base_config(rpm, kFitSeconds + eval_seconds, alpha);
  const double ratio = static_cast<double>(base.p) / base.p_r;
  std::vector<double> raw, hwang, fourier, sincos, ref;
  double revs = 0.0;
  for (int k = 0; k < seeds; ++k) {
    const std::vector<Record> recs = simulate_records(seeded(base, static_cast<std::uint64_t>(k) + 1));
    SinCosLeastSquares ls(ls_config());
    AngleFourierConfig fc;
    fc.max_order = 6;
    AngleErrorFourier af(fc);
    HwangIntegralEstimator hw(HwangIntegralConfig{});
    std::size_t i = 0;
    for (; i < recs.size() && recs[i].t < kFitSeconds; ++i) {
      const Record& r = recs[i];
      ls.add(r.s, r.c, r.theta_ref);
      af.add(r.theta_ref, r.rd);
      (void)hw.update(r.t, r.rd);
    }
    const auto fit_ls = ls.solve_reference();
    const auto fit_f = af.solve();
    if (!fit_ls || !fit_f || hw.revolutions() == 0) continue;
    const SinCosCorrection corr = SinCosCorrection::from_fit(*fit_ls);
    const double alpha_hw = hw.alpha();
    RippleProbe p_raw(ratio), p_hw(ratio), p_f(ratio), p_sc(ratio), p_ref(ratio);
    for (; i < recs.size(); ++i) {
      const Record& r = recs[i];
      p_raw.add(r.rd, r);
      p_hw.add(wrap_2pi(r.rd + amplitude_imbalance_eps(alpha_hw, r.rd)), r);
      p_f.add(fit_f->compensate(r.rd), r);
      p_sc.add(corrected_angle(corr, r.s, r.c), r);
      p_ref.add(r.theta_ref, r);
    }
    raw.push_back(p_raw.amplitude_2x());
    hwang.push_back(p_hw.amplitude_2x());
    fourier.push_back(p_f.amplitude_2x());
    sincos.push_back(p_sc.amplitude_2x());
    ref.push_back(p_ref.amplitude_2x());
    revs = static_cast<double>(p_ref.revolutions());
  }
  RippleStudy out;
  out.rpm = rpm;
  out.alpha = alpha;
  out.seeds = static_cast<int>(raw.size());
  out.eval_revolutions = revs;
  out.samples_per_revolution = base.sample_rate_hz / (rpm / 60.0 * base.p);
  out.raw = mean_of(raw);
  out.hwang = mean_of(hwang);
  out.fourier = mean_of(fourier);
  out.sincos = mean_of(sincos);
  out.ref = mean_of(ref);
  const double n_total = revs * out.samples_per_revolution;
  out.floor_rd = ripple_floor(base, rd_quantization_sigma(base), n_total);
  out.floor_sincos = ripple_floor(base, effective_sincos_sigma(base) / base.amplitude_counts, n_total);
  return out;
}

}  // namespace resolver::accuracy
