// The composed forward model of the sensor chain, built from the registry's
// hooks (effect.h): what the simulator runs and what the generic signature test
// differentiates. Pure maths; the only state is the motion effects' (backlash).
//
//   true theta_m(t) ──time shift (delay)──► theta_m(t - d) ──motion hooks──► seen theta_m
//     ──x p_r + angle shift (mounting)──► theta ──windings at time t: fundamental, additive, gain, offset──► envelopes
//     envelopes ──channel timing──► converter input (cos at t + converter_cos_dt) ──R/D loop, rd_bits──► rd_angle
//               └─────────────────► DSP samples   (cos at t + dsp_cos_dt) ──+ noise──► sin/cos counts
//   theta_e = p theta_m ──drive frame (mounting)──► machine currents ──inverter──► ──sensors: gain, offset──► i_a, i_b, i_c
#pragma once

#include <vector>

#include "daemon/core/effects/chain_values.h"
#include "daemon/core/effects/phase_currents.h"
#include "daemon/core/effects/sin_cos.h"

namespace resolver {

class ForwardChain {
 public:
  /// Captures the active effects of `values`. p_r, p >= 1. Throws std::invalid_argument
  /// (from Effect::validate) when an active effect's parameter set is invalid.
  ForwardChain(const ChainValues& values, int p_r, int p);

  /// [s] the resolver's signals at time t are those of t - time_shift() (delay).
  [[nodiscard]] double time_shift() const { return time_shift_; }
  /// The resolver electrical angle [rad, continuous] the resolver sees when the true
  /// mechanical angle (already at t - time_shift) is theta_m [rad] at speed omega_m
  /// [rad/s]. `commit`: a sample instant (motion effects with a state update it).
  [[nodiscard]] double resolver_angle(double theta_m, double omega_m, bool commit);
  /// Unit-amplitude envelopes at resolver angle theta [rad] and time t [s] since the
  /// log's first sample, before noise. Only effects that change in time
  /// (Effect::windings_in_time: envelope_drift) read t; for a chain without them
  /// the default t = 0 is every time.
  [[nodiscard]] SinCos envelopes(double theta, double t = 0.0) const;
  [[nodiscard]] const ChannelTiming& timing() const { return timing_; }
  [[nodiscard]] const ConverterSpec& converter() const { return converter_; }
  [[nodiscard]] const Impairments& impairments() const { return impairments_; }
  /// [A] the machine currents for the command (i_d_cmd, i_q_cmd) [A] in the drive's
  /// frame at true motor electrical angle theta_e [rad] (drive frame, inverter).
  [[nodiscard]] PhaseCurrents machine_currents(double i_d_cmd, double i_q_cmd, double theta_e) const;
  /// [A] what the sensors report for the machine currents `actual` (before noise).
  [[nodiscard]] PhaseCurrents measured_currents(const PhaseCurrents& actual, double theta_e) const;
  /// Changes one parameter (a drift the simulator applies sample by sample).
  /// `param` must be a valid index; throws std::invalid_argument out of range.
  void set_value(const Effect& effect, std::size_t param, double value);

 private:
  struct Active {
    const Effect* effect;
    std::vector<double> values;
    MotionState state;
  };
  void refresh();

  ChainValues values_;
  int p_r_, p_;
  std::vector<Active> active_;
  double time_shift_ = 0.0;
  double drive_offset_ = 0.0;
  ChannelTiming timing_;
  ConverterSpec converter_;
  Impairments impairments_;
};

}  // namespace resolver
