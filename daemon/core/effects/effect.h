// One effect of the sensor chain, self-described: the unit the effect registry
// (registry.h) lists and everything else is generated from — the catalog table,
// the spec parser, --list-effects, the simulator's forward model and validation,
// truth files, discovery's columns, compensation and docs/EFFECTS.md.
//
// Architecture of the model library (daemon/core/model/, pure maths: no I/O,
// no clocks, no globals but the registry's constant list):
//
//   Effect (this file) ── one subclass per physical effect, one file pair each in
//   │                     daemon/core/effects/, one line in registry.cpp
//   ├─ parameters:        one constexpr ParamInfo list per effect (param_info.h): name,
//   │                     unit, description, range, neutral value, written once. The
//   │                     hooks, the effect's forward functions, the simulator and the
//   │                     tests read and write values by name through the type
//   │                     generated from that list, ParamSet<list> (param_set.h)
//   ├─ forward hooks:     the simulator's chain calls them at the stage where the
//   │                     effect acts (forward_chain.h):
//   │                       motion      what the resolver sees of the true angle (delay, eccentricity, backlash)
//   │                       windings    the envelopes of the resolver angle (quadrature, harmonics, gain, offsets),
//   │                                   and of time for those that drift (envelope_drift)
//   │                       channels    when each channel is taken (channel delay, sampling skew)
//   │                       converter   the R/D loop and its resolution
//   │                       currents    drive frame, inverter, current sensors
//   │                       noise       the ADCs
//   └─ signature:         per parameter, the derivative of every signal the fit
//                         sees (signature.h): position error of the R/D angle,
//                         sin/cos envelopes, i_d/i_q. A generic test checks each
//                         one against the finite-difference derivative of the
//                         forward chain, so a sign or scale slip fails.
//   Model (model.h) ────── active effects + values + covariance: fit, estimate_t,
//                         compensation, persisted calibration, export, reports.
//
// Errors: functions that can fail say so and throw std::invalid_argument with a
// message naming the effect, parameter, value and the valid range (the one error
// style of the library); everything else cannot fail.
//
// Units: angles [rad] (resolver electrical unless a name says mechanical or motor
// electrical), time [s], currents [A], envelopes as a fraction of their nominal
// amplitude (sin_cos.h). Conventions: daemon/core/angles.h (docs/ARCHITECTURE.md §3).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "daemon/core/effects/param_info.h"
#include "daemon/core/effects/phase_currents.h"
#include "daemon/core/effects/sin_cos.h"
#include "daemon/core/effects/signature.h"
#include "daemon/core/effects/tracking_loop.h"

namespace resolver {

/// Where in the chain an effect acts (for the catalog and for which signals it can change).
enum class EffectStage : std::uint8_t {
  kMotion,      ///< the angle the resolver sees (delay, eccentricity, mounting, backlash)
  kWindings,    ///< the resolver's envelopes
  kChannels,    ///< timing of the channels (channel delay, sampling skew)
  kConverter,   ///< the R/D converter (tracking loop, quantization)
  kCurrents,    ///< phase currents (drive, inverter, sensors)
  kNoise,       ///< measurement noise and impairments (sets the floor, never fitted)
};

/// Sub-stages of the windings, applied in this order to every effect's hook.
enum class WindingStage : std::uint8_t {
  kFundamental,  ///< replace the fundamental pair (quadrature)
  kAdditive,     ///< add to both channels (harmonics)
  kGain,         ///< scale a channel (amplitude imbalance)
  kOffset,       ///< add constants after demodulation (offsets)
};

/// Sub-stages of the current chain, applied in this order.
enum class CurrentStage : std::uint8_t {
  kInverter,  ///< distortion of the machine currents (dead time)
  kSensorGain,
  kSensorOffset,
};

/// When the cos channel is taken relative to the sin channel [s] (> 0: later).
struct ChannelTiming {
  double converter_cos_dt = 0.0;  ///< the R/D converter's cos input (analog path)
  double dsp_cos_dt = 0.0;        ///< the DSP's sampled cos envelope
};

/// The R/D converter the chain simulates.
struct ConverterSpec {
  TrackingLoopParams loop;  ///< the type-II loop (tracking_loop.h); omega_n = 0: ideal (atan2)
  int rd_bits = 16;      ///< [bits] resolution of the rd_angle field
};

/// Measurement impairments the chain adds (never fitted; they set the floor).
struct Impairments {
  double sigma_sc = 0.0;         ///< [counts] white noise on each sin/cos ADC sample
  double sigma_i = 0.0;          ///< [A] white noise on each phase current sample
  double outlier_rate = 0.0;     ///< [1/s] impulsive samples on the sin channel
  double outlier_size = 0.0;     ///< [counts] their size (sign random)
  double current_outlier_rate = 0.0;      ///< [1/s] impulsive samples on phase current a
  double current_outlier_size = 0.0;      ///< [A] their size
  double current_outlier_positive = 0.5;  ///< share of them that are positive
};

/// The highest harmonic orders an effect's columns use, of the resolver angle theta,
/// the mechanical angle theta_m and the motor angle theta_e: a fit needs the log to
/// cover every one of 2N bins of each angle (discovery's coverage check).
struct HarmonicOrders {
  int theta = 0;
  int theta_m = 0;
  int theta_e = 0;
};

/// What discovery's residual shows, for effects whose candidates follow it.
class ResidualSpectrum {
 public:
  enum class Angle : std::uint8_t { kResolver, kMechanical };
  virtual ~ResidualSpectrum() = default;
  /// The residual's harmonic orders of `angle` that stand above its noise, from
  /// `lowest`, largest first, at most `most`.
  [[nodiscard]] virtual std::vector<int> significant(Angle angle, int lowest, int most) const = 0;
  /// The same, only the few largest that discovery tries one order at a time.
  [[nodiscard]] virtual std::vector<int> strongest(Angle angle, int lowest) const = 0;
};

/// A candidate term discovery tries for an effect: its parameters by name, grouped
/// by harmonic order. One group: the term as listed (skipped when a name is
/// unknown or already in the model). A family: every group's parameters not yet in
/// the model, tried as one step when enough orders are left (ranking.cpp).
struct CandidateParams {
  std::vector<std::vector<std::string>> groups;
  bool family = false;
};

/// The part of an effect's angle error that depends on speed or direction and
/// not on the angle: [rad, resolver electrical] per_speed_s * omega +
/// per_direction_rad * sign(omega), omega the resolver electrical speed [rad/s].
/// A calibration table keeps these as scalars beside its static correction
/// (daemon/core/model/calibration_table.h).
struct MotionTerms {
  double per_speed_s = 0.0;
  double per_direction_rad = 0.0;
};

/// State a motion hook may keep between samples (backlash's play).
struct MotionState {
  bool started = false;
  double value = 0.0;
};

class Effect {
 public:
  Effect() = default;
  virtual ~Effect() = default;
  Effect(const Effect&) = delete;
  Effect& operator=(const Effect&) = delete;
  Effect(Effect&&) = delete;
  Effect& operator=(Effect&&) = delete;

  // ---- self-description ----------------------------------------------------
  [[nodiscard]] virtual std::string_view name() const = 0;
  /// One line: forward model and signature.
  [[nodiscard]] virtual std::string_view description() const = 0;
  /// Paper equations or the header that derives it.
  [[nodiscard]] virtual std::string_view source() const = 0;
  /// One sentence of physics for "what is missing" explanations.
  [[nodiscard]] virtual std::string_view physics() const = 0;
  [[nodiscard]] virtual std::span<const ParamInfo> params() const = 0;
  [[nodiscard]] virtual EffectStage stage() const = 0;
  /// False for effects that only set the floor (noise, quantization, outliers).
  [[nodiscard]] virtual bool fittable() const { return true; }
  /// The signature needs the reference angle (an absolute or mechanical quantity).
  [[nodiscard]] virtual bool needs_reference() const { return false; }
  /// Identifiable only when the reference's zero is the rotor d axis (a constant
  /// position error is otherwise the reference's own zero: PrepareOptions).
  [[nodiscard]] virtual bool needs_aligned_reference() const { return false; }
  /// Acts on the phase currents only.
  [[nodiscard]] virtual bool current_side() const { return stage() == EffectStage::kCurrents; }
  /// Only a log with changing speed or reversals separates it from the others
  /// (tracking loop, delay and backlash look like constants at one speed).
  [[nodiscard]] virtual bool needs_speed_change() const { return false; }
  /// The motion (or signal) without which the effect is not identifiable at all: at
  /// one speed in one direction its signature is a constant or a turn of the other
  /// effects' harmonics (delay: omega d; the loop: H(j k omega) per order), and in one
  /// direction a play is a constant. The loop filters only the R/D angle, so with the
  /// sin/cos envelopes beside it (an unfiltered view of the same error harmonics) one
  /// speed shows H(j k omega) directly: kSpeedChangeOrSinCos. Discovery lists the
  /// effect as "not identifiable here" with what to record instead of proposing it.
  enum class Needs : std::uint8_t { kNothing, kSpeedChangeOrReversal, kSpeedChangeOrSinCos, kReversal };
  [[nodiscard]] virtual Needs identifiable_with() const { return Needs::kNothing; }
  /// The candidate terms discovery tries for this effect, from the residual's
  /// spectrum (a harmonic at the orders the residual shows, with its phase, and as a
  /// family when `families`: offline only). nullopt: its default parameters, once,
  /// when the model lacks the effect.
  [[nodiscard]] virtual std::optional<std::vector<CandidateParams>> residual_candidates(
      const ResidualSpectrum& /*residual*/, bool /*families*/) const {
    return std::nullopt;
  }
  /// Terms of other effects that land, at first order and at this p_r, on the same
  /// harmonics of the envelopes as the fitted parameters `params` (first_order_aliases.h:
  /// a mechanical pair of a whole electrical order and that order's winding terms), as
  /// effect references. Discovery fits each in place of the model's term, since the
  /// residual no longer asks for the orders the model's alias took (ranking.cpp).
  [[nodiscard]] virtual std::vector<std::string> first_order_aliases(std::span<const int> /*params*/,
                                                                     int /*p_r*/) const {
    return {};
  }
  /// The harmonic orders the columns of the fitted parameters `params` use.
  /// Default by stage: windings/channels/converter 2 theta, motion 0, currents 1 theta_e.
  [[nodiscard]] virtual HarmonicOrders orders(std::span<const int> params) const;
  /// Checks a whole parameter set beyond the per-parameter ranges (e.g. the play
  /// must be smaller than a turn). Throws std::invalid_argument naming the effect
  /// and parameter. Default: nothing more to check.
  virtual void validate(Values /*v*/) const {}
  /// True when the values change the chain from ideal. Default: a parameter is
  /// away from its neutral value.
  [[nodiscard]] virtual bool active(Values v) const;
  /// True when the effect's whole angle error is speed- or direction-dependent
  /// (motion_terms()): a table over the angle leaves it out and keeps the terms.
  [[nodiscard]] virtual bool has_motion_terms() const { return false; }
  /// The speed and direction terms of the error at values `v` (resolver pole
  /// pairs p_r); only for effects with has_motion_terms().
  [[nodiscard]] virtual MotionTerms motion_terms(Values /*v*/, int /*p_r*/) const { return {}; }

  // ---- forward hooks (forward_chain.h calls them; defaults do nothing) -------
  /// [s] the resolver's signals are those of time t - shift (delay).
  [[nodiscard]] virtual double resolver_time_shift(Values /*v*/) const { return 0.0; }
  /// The mechanical angle [rad, continuous] the resolver sees, given what the
  /// earlier motion effects made of the true angle, and the mechanical speed [rad/s].
  /// `commit`: this is the sample instant, so the effect may update `state` (the
  /// chain also asks at intermediate instants of the converter's integration).
  [[nodiscard]] virtual double seen_mech_angle(Values /*v*/, double theta_m, double /*omega_m*/,
                                               MotionState& /*state*/, bool /*commit*/) const {
    return theta_m;
  }
  /// [rad, resolver electrical] added to the resolver angle (mounting offset: p_r theta_0 / p).
  [[nodiscard]] virtual double resolver_angle_shift(Values /*v*/, int /*p_r*/, int /*p*/) const { return 0.0; }
  /// Modifies the unit envelopes at resolver angle theta [rad] at one sub-stage.
  virtual void windings(Values /*v*/, WindingStage /*stage*/, double /*theta*/, SinCos& /*env*/) const {}
  /// The same hook for windings that change in time (envelope_drift): t [s] is the
  /// time since the log's first sample (the simulator's sample time, the fit's
  /// SignatureRow::t). The forward chain calls this one; the default is the
  /// time-invariant windings() above. An effect that overrides it must not be
  /// envelope_only() (the fit's envelope spectrum is a function of the angle alone:
  /// a generic registry test checks that) and gives its time dependence in signature().
  virtual void windings_in_time(Values v, WindingStage stage, double theta, double /*t*/, SinCos& env) const {
    windings(v, stage, theta, env);
  }
  /// Adds to the channel timing.
  virtual void channel_timing(Values /*v*/, ChannelTiming& /*timing*/) const {}
  /// Sets the converter's dynamics or resolution.
  virtual void converter(Values /*v*/, ConverterSpec& /*spec*/) const {}
  /// [rad, motor electrical] the drive's current frame leads the rotor by this (mounting offset).
  [[nodiscard]] virtual double drive_frame_offset(Values /*v*/) const { return 0.0; }
  /// Modifies the phase currents at one sub-stage; theta_e [rad] is the true motor angle.
  virtual void currents(Values /*v*/, CurrentStage /*stage*/, double /*theta_e*/, PhaseCurrents& /*i*/) const {}
  /// Adds measurement impairments.
  virtual void impairments(Values /*v*/, Impairments& /*imp*/) const {}

  // ---- signature (the fit) ---------------------------------------------------
  /// For each parameter i, the derivative of every signal with respect to it at
  /// the values `v`, into out.col(i). Only for fittable effects.
  virtual void signature(const SignatureRow& row, const AngleBasis& basis, Values v, SignatureColumns& out) const;
  /// True when contribution() is exactly sum(column x value) with columns that do
  /// not depend on the values: the fit then skips contribution() (a speed-up only).
  /// Effects that override contribution() must return false.
  [[nodiscard]] virtual bool linear_in_params() const { return true; }
  /// The effect's own contribution to every signal at values `v` (the part of the
  /// prediction it adds). Default: sum over parameters of column x value, right
  /// for effects whose signature is linear in their parameters.
  virtual void contribution(const SignatureRow& row, const AngleBasis& basis, Values v, SignalValues& out) const;
  /// Effects that move or filter the angle the resolver's errors are functions of
  /// set the transform every other effect's harmonics go through (tracking loop:
  /// H(j k omega); delay: theta(t - d); mounting offset, backlash, eccentricity,
  /// mechanical harmonics: the seen angle's shift). Per row: a shift may vary.
  virtual void configure_basis(const SignatureRow& /*row*/, Values /*v*/, BasisTransform& /*t*/) const {}
  /// True when configure_basis does something: the model's prediction is then not
  /// linear in this effect's parameters even if its own columns are (Gauss-Newton
  /// iterates).
  [[nodiscard]] virtual bool shapes_basis() const { return false; }
  /// True when the effect's whole action is its windings() hook on the envelopes of
  /// the seen angle (gain, quadrature, winding harmonics, offsets): the fit then
  /// evaluates all such effects together, exactly through atan2 and hypot
  /// (daemon/core/model/envelope_spectrum.h), and signature() serves only as their
  /// first-order description (the registry's signature test, ranking at zero).
  [[nodiscard]] virtual bool envelope_only() const { return false; }
};

/// The self-description every effect has, as data.
struct EffectText {
  std::string_view name;
  std::string_view description;  ///< one line: forward model and signature
  std::string_view source;       ///< paper equations or the header that derives it
  std::string_view physics;      ///< one sentence for "what is missing"
};

/// Base for the registry's effects: the self-description from data, the hooks overridden.
class BasicEffect : public Effect {
 public:
  BasicEffect(const EffectText& text, std::span<const ParamInfo> params, EffectStage stage)
      : text_(text), params_(params), stage_(stage) {}
  [[nodiscard]] std::string_view name() const final { return text_.name; }
  [[nodiscard]] std::string_view description() const final { return text_.description; }
  [[nodiscard]] std::string_view source() const final { return text_.source; }
  [[nodiscard]] std::string_view physics() const final { return text_.physics; }
  [[nodiscard]] std::span<const ParamInfo> params() const final { return params_; }
  [[nodiscard]] EffectStage stage() const final { return stage_; }

 private:
  EffectText text_;
  std::span<const ParamInfo> params_;
  EffectStage stage_;
};

}  // namespace resolver
