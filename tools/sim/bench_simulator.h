// The bench simulator: a motor on a dyno with a resolver, an R/D converter, a
// current-controlled inverter and a reference encoder, producing the CAN frames
// of the default bench layout (docs/ARCHITECTURE.md §4) with chosen catalog effects.
//
// Per control sample k (t_k = k / sample_rate_hz):
//   theta_m(t)  from the speed profile (exact integral), theta = p_r theta_m, theta_e = p theta_m
//   theta_s(t)  = the angle the resolver sees: the registry's forward chain
//                 (daemon/core/effects/forward_chain.h) at t - delay, through the
//                 motion effects (backlash, eccentricity, mechanical harmonics, mounting)
//   sin/cos     = amplitude_counts * envelopes: sin of theta_s(t_k), cos of
//                 theta_s(t_k + dsp_cos_dt) (channel delay, sampling skew), each at
//                 its own time (drifting windings: envelope_drift) + noise,
//                 outliers                                             -> i16 counts
//   rd_angle    = the tracking loop, integrated continuously from t_{k-1} to t_k on
//                 the noise-free envelopes with the converter's own channel timing
//                 (ADC noise and the DSP's sampling skew are the DSP's), rounded to
//                 rd_bits                                              -> u16
//   currents    = the forward chain's machine currents: ideal current control in the
//                 drive frame theta_e + theta_0 (Hwang eqs. 11-12) with the inverter's
//                 distortion; then the current sensors + noise          -> mA
//   reference   = theta_m wrapped, 2^32 counts per mechanical turn     -> u32
// The same effect units (daemon/core/effects, registry.h) are what the fit uses.
//
// Randomness: one std::mt19937_64 seeded with `seed`; the same SimConfig gives the
// same samples and frames.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "daemon/core/effects/chain_values.h"
#include "daemon/core/effects/forward_chain.h"
#include "daemon/core/effects/noise.h"
#include "daemon/core/effects/quantization.h"
#include "daemon/core/effects/tracking_loop.h"
#include "drivers/can_frame.h"
#include "tools/sim/speed_profile.h"

namespace resolver {

/// The simulator's default sensor chain: ideal resolver, but a realistic R/D
/// converter and ADC noise.
///  - tracking loop omega_n = 3000 rad/s, zeta = 0.7: the order of an AD2S1205 /
///    AD2S1210 in 12-bit mode. Their datasheet loop model (k1 k2 ~ 8e7 s^-2 with a
///    compensator zero at ~1000 rad/s and pole at ~11000 rad/s) reduces at low
///    frequency to a second-order loop with omega_n ~ 2.7e3 rad/s; zeta = 0.7 is
///    the textbook design damping. With p_r = 3 the 2theta ripple of amplitude
///    imbalance sees |H| = 1.002 at 200 r/min, 1.04 at 1000 r/min, 1.25 (and
///    -14 deg) at 3000 r/min: negligible at Hwang's speed, visible when swept.
///  - noise sigma_sc = 2 counts (~1e-4 of a 26000-count amplitude: a good 12-14 bit
///    ADC path), sigma_i = 0.02 A (about one LSB of a 12-bit ADC over +-50 A).
[[nodiscard]] ChainValues default_sim_chain();

struct SimConfig {
  /// Hwang's setup: 200 r/min for 5 s.
  std::vector<SpeedSegment> profile{{5.0, 200.0, 200.0}};
  int p_r = 3;  ///< resolver pole pairs (Hwang: 6-pole resolver)
  int p = 3;    ///< motor pole pairs (Hwang: 6-pole PMSM)
  /// [bits] R/D resolution. Same quantity as chain.quantization.rd_bits: set either;
  /// both non-default and different is an error. Default: the effect's neutral value.
  int rd_bits = static_cast<int>(QuantizationParams::info("rd_bits").neutral);
  /// [Hz] control-sample rate: 3 frames per sample must fit a 1 Mbit/s bus
  /// (~8000 classic 8-byte frames/s), so 2 kHz (6000 frames/s) by default.
  double sample_rate_hz = 2000;
  double amplitude_counts = 26000;  ///< [counts] nominal envelope amplitude (full scale 32767)
  double i_d_cmd = 0;               ///< [A] commanded d current
  double i_q_cmd = 10;              ///< [A] commanded q current
  bool reference = true;            ///< send REFERENCE_ANGLE frames
  ChainValues chain = default_sim_chain();
  std::uint64_t seed = 1;
  std::int64_t start_time_us = 1700000000000000;  ///< [us] timestamp of sample 0
  double theta_m0 = 0;                            ///< [rad] mechanical angle at t = 0
  /// [1/s] the amplitude imbalance drifts linearly in time, alpha(t) = alpha + drift t
  /// (a winding warming up). NOT a catalog effect: it exists so tests can check that
  /// model discovery does not force a catalog name onto an error outside the catalog.
  double alpha_drift_per_s = 0;
  std::string iface = "can0";                     ///< interface name written into the frames
};

struct SimSample {
  std::int64_t t_us;      ///< [us] timestamp
  std::uint8_t counter;   ///< index mod 256 (the frames' counter byte)
  std::uint64_t index;    ///< sample number from 0
  double theta_m;         ///< [rad] true mechanical angle, wrapped [0, 2pi)
  double theta;           ///< [rad] true resolver electrical angle, wrapped [0, 2pi)
  double theta_e;         ///< [rad] true motor electrical angle, wrapped [0, 2pi)
  double omega_m;         ///< [rad/s] true mechanical speed
  std::int16_t sin_counts;
  std::int16_t cos_counts;
  std::uint16_t rd_counts;  ///< u16 rd_angle field (low 16 - rd_bits bits zero)
  double rd_angle;          ///< [rad] the angle rd_counts stands for, as transmitted
  std::int16_t i_a_ma;      ///< [mA]
  std::int16_t i_b_ma;
  std::int16_t i_c_ma;
  std::uint32_t ref_counts;  ///< reference mechanical angle, 2^32 counts per turn
};

class BenchSimulator {
 public:
  /// Throws std::invalid_argument whose message names the SimConfig field at
  /// fault and the valid range.
  explicit BenchSimulator(SimConfig config);

  /// Produces the next sample; returns false (and leaves `out` alone) at the end.
  bool next(SimSample& out);

  /// Appends this sample's frames: RESOLVER_SAMPLE at t_us, PHASE_CURRENTS at
  /// t_us + 1, REFERENCE_ANGLE at t_us + 2 (if enabled), then BENCH_INFO at the next
  /// microsecond on the first sample and on every sample that starts a new 100 ms
  /// of sim time (10 Hz, docs/ARCHITECTURE.md §4). Frames carry config().iface.
  void append_frames(const SimSample& s, std::vector<CanFrame>& out) const;

  [[nodiscard]] std::uint64_t total_samples() const { return total_; }
  [[nodiscard]] const SimConfig& config() const { return config_; }
  [[nodiscard]] const SpeedProfile& profile() const { return profile_; }
  /// [us] timestamp of sample `index`.
  [[nodiscard]] std::int64_t sample_time_us(std::uint64_t index) const;

 private:
  [[nodiscard]] double sample_time_s(std::uint64_t index) const;
  [[nodiscard]] double theta_m_at(double t) const;

  /// [rad] the resolver electrical angle the chain sees at time t for its sin channel
  /// (t - delay) with the cos channel `cos_dt` [s] later; commit at sample instants.
  [[nodiscard]] double seen_angle(double t, bool commit);
  [[nodiscard]] SinCos converter_envelopes(double t);

  SimConfig config_;
  SpeedProfile profile_;
  ForwardChain chain_;
  TrackingLoop loop_;
  NoiseEngine engine_;
  std::uint64_t total_ = 0;
  std::uint64_t index_ = 0;
  double alpha0_ = 0.0;  ///< chain alpha at t = 0 (the forward chain's alpha follows the drift)
};

/// Frames per second the configuration puts on the bus (for the bus-load check).
[[nodiscard]] double frames_per_second(const SimConfig& config);

}  // namespace resolver
