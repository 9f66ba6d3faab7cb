// A log of the default bench simulated in memory (BenchSimulator: R/D loop
// omega_n = 3000 rad/s, ADC noise 2 counts, 16-bit R/D) as discovery's input, with
// the given effect specs ("amplitude_imbalance:alpha=0.003"), speed profile and p_r.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "daemon/core/angles.h"
#include "daemon/core/discovery/model_discovery.h"
#include "daemon/decode/bench_layout.h"
#include "tools/sim/bench_simulator.h"

namespace resolver {

inline DiscoveryInput simulate(const std::vector<std::string>& specs, std::vector<SpeedSegment> profile = {{5.0, 200.0, 200.0}},
                        double alpha_drift_per_s = 0.0, std::uint64_t seed = 1, int p_r = 0) {
  SimConfig cfg;
  cfg.seed = seed;
  if (p_r > 0) cfg.p_r = p_r;  // else the bench's (3)
  cfg.profile = std::move(profile);
  cfg.alpha_drift_per_s = alpha_drift_per_s;
  for (const auto& s : specs) {
    cfg.chain.apply_spec(s);
  }
  BenchSimulator sim(cfg);
  DiscoveryInput in;
  in.p_r = cfg.p_r;
  in.p = cfg.p;
  SimSample s{};
  while (sim.next(s)) {
    Sample d;
    d.t = static_cast<double>(s.t_us - cfg.start_time_us) * 1e-6;
    d.has_rd = true;
    d.theta_rd = s.rd_angle;
    d.has_sincos = true;
    d.sin = s.sin_counts;
    d.cos = s.cos_counts;
    d.has_ref = true;
    d.theta_m_ref = static_cast<double>(s.ref_counts) * (kTwoPi / 4294967296.0);
    d.has_currents = true;
    d.i_a = s.i_a_ma * bench::kCurrentAmpsPerBit;
    d.i_b = s.i_b_ma * bench::kCurrentAmpsPerBit;
    d.i_c = s.i_c_ma * bench::kCurrentAmpsPerBit;
    in.samples.push_back(d);
  }
  return in;
}

}  // namespace resolver
