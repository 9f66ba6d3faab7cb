// Shared data generators for the estimator tests (sin/cos LS, Fourier fit,
// compensation, CRLB). Two sources:
//  - forward_samples(): the effect registry's forward chain (forward_chain.h)
//    plus Gaussian noise in double precision, angles uniform over whole
//    revolutions: exactly the CRLB's assumptions, for the statistical tests;
//  - simulate(): the bench simulator (tools/sim), i16 counts, R/D converter,
//    reference encoder: what the daemon sees.
#pragma once

#include <cmath>
#include <cstdint>
#include <vector>

#include "daemon/core/angles.h"
#include "daemon/core/effects/forward_chain.h"
#include "daemon/core/effects/noise.h"
#include "tests/unit/effects/chain_test_support.h"
#include "tools/sim/bench_simulator.h"

namespace resolver::test {

struct EnvelopeSample {
  double theta = 0.0;  ///< [rad] true resolver electrical angle
  double s = 0.0;      ///< [counts]
  double c = 0.0;      ///< [counts]
};

/// n samples at theta_k = theta0 + 2pi revs k / n (uniform over `revs` whole
/// revolutions), envelopes amplitude * chain.envelopes(theta) + N(0, sigma^2).
inline std::vector<EnvelopeSample> forward_samples(const ForwardChain& chain, double amplitude, double sigma,
                                                   int n, int revs, double theta0, std::uint64_t seed) {
  NoiseEngine engine(seed);
  std::vector<EnvelopeSample> out;
  out.reserve(static_cast<std::size_t>(n));
  for (int k = 0; k < n; ++k) {
    const double theta = theta0 + kTwoPi * revs * k / n;
    const SinCos sc = chain.envelopes(theta);
    const double s = amplitude * sc.s + gaussian_noise(engine, sigma);
    const double c = amplitude * sc.c + gaussian_noise(engine, sigma);
    out.push_back({wrap_2pi(theta), s, c});
  }
  return out;
}

struct SimRecord {
  double t = 0.0;          ///< [s]
  double theta = 0.0;      ///< [rad] true resolver electrical angle (simulator truth)
  double theta_ref = 0.0;  ///< [rad] resolver electrical angle from the u32 reference frame
  double s = 0.0, c = 0.0; ///< [counts] as transmitted (i16)
  double rd = 0.0;         ///< [rad] R/D angle as transmitted
};

/// Runs the bench simulator and keeps what the estimators need.
inline std::vector<SimRecord> simulate(const SimConfig& config) {
  BenchSimulator sim(config);
  std::vector<SimRecord> out;
  out.reserve(sim.total_samples());
  SimSample s{};
  constexpr double kRefCountsPerTurn = 4294967296.0;  // docs/ARCHITECTURE.md §4: 2^32 counts per mechanical turn
  while (sim.next(s)) {
    SimRecord r;
    r.t = static_cast<double>(s.index) / config.sample_rate_hz;
    r.theta = s.theta;
    r.theta_ref = wrap_2pi(config.p_r * (static_cast<double>(s.ref_counts) / kRefCountsPerTurn) * kTwoPi);
    r.s = s.sin_counts;
    r.c = s.cos_counts;
    r.rd = s.rd_angle;
    out.push_back(r);
  }
  return out;
}

/// Effective per-channel noise of the simulator's i16 samples [counts]: Gaussian
/// sigma plus rounding to integers (uniform, variance 1/12 count^2), independent.
inline double sim_sigma(const SimConfig& config) {
  const double g = config.chain.get("noise", "sigma_sc");
  return std::sqrt(g * g + 1.0 / 12.0);
}

}  // namespace resolver::test
