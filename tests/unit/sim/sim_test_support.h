// Helpers for the simulator's effect tests: run a configuration to the end, a
// quiet chain (no noise, ideal converter) so only the effect under test is in
// the samples, which signals two runs differ in, and the angles and currents a
// sample carries decoded as the daemon would.
#pragma once

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include "daemon/core/angles.h"
#include "daemon/core/effects/phase_currents.h"
#include "tools/sim/bench_simulator.h"

namespace resolver::test {

/// Every sample of a run.
[[nodiscard]] inline std::vector<SimSample> run(const SimConfig& c) {
  BenchSimulator sim(c);
  std::vector<SimSample> out;
  SimSample s{};
  while (sim.next(s)) out.push_back(s);
  return out;
}

/// A hold at `rpm` for `seconds` with the noise off and an ideal converter
/// (tracking_loop omega_n = 0): the samples carry only the effect under test,
/// rounding to whole counts and the 16-bit R/D resolution.
[[nodiscard]] inline SimConfig quiet(double rpm, double seconds) {
  SimConfig c;
  c.profile = {{seconds, rpm, rpm}};
  c.chain.set("noise", "sigma_sc", 0.0);
  c.chain.set("noise", "sigma_i", 0.0);
  c.chain.set("tracking_loop", "omega_n", 0.0);
  return c;
}

// Which recorded signals differ between two runs.
constexpr unsigned kSinCos = 1U;
constexpr unsigned kRd = 2U;
constexpr unsigned kCurrents = 4U;
constexpr unsigned kReference = 8U;

[[nodiscard]] inline unsigned changed_signals(const std::vector<SimSample>& a, const std::vector<SimSample>& b) {
  unsigned mask = 0;
  for (std::size_t i = 0; i < std::min(a.size(), b.size()); ++i) {
    if (a[i].sin_counts != b[i].sin_counts || a[i].cos_counts != b[i].cos_counts) mask |= kSinCos;
    if (a[i].rd_counts != b[i].rd_counts) mask |= kRd;
    if (a[i].i_a_ma != b[i].i_a_ma || a[i].i_b_ma != b[i].i_b_ma || a[i].i_c_ma != b[i].i_c_ma) mask |= kCurrents;
    if (a[i].ref_counts != b[i].ref_counts) mask |= kReference;
  }
  return mask;
}

/// [rad] the reference encoder's mechanical angle as transmitted (2^32 counts per turn, docs/ARCHITECTURE.md §4).
[[nodiscard]] inline double reference_angle_m(const SimSample& s) {
  return static_cast<double>(s.ref_counts) / 4294967296.0 * kTwoPi;
}

/// [rad] the R/D angle's position error against the reference, eps = p_r theta_ref_m - theta_rd
/// (docs/ARCHITECTURE.md §3), wrapped to [-pi, pi).
[[nodiscard]] inline double rd_error_vs_reference(const SimSample& s, int p_r) {
  return wrap_pi(p_r * reference_angle_m(s) - s.rd_angle);
}

/// Clarke + Park (docs/ARCHITECTURE.md §3) of a sample's decoded currents [A].
[[nodiscard]] inline DqCurrents sample_dq(const SimSample& s, double theta_e) {
  const double i_alpha = s.i_a_ma * 1e-3;
  const double i_beta = (s.i_b_ma - s.i_c_ma) * 1e-3 / std::numbers::sqrt3;
  return {i_alpha * std::cos(theta_e) + i_beta * std::sin(theta_e),
          -i_alpha * std::sin(theta_e) + i_beta * std::cos(theta_e)};
}

}  // namespace resolver::test
