#include "daemon/core/effects/forward_chain.h"

#include "daemon/core/effects/phase_currents.h"

namespace resolver {

ForwardChain::ForwardChain(const ChainValues& values, int p_r, int p) : values_(values), p_r_(p_r), p_(p) {
  values_.validate();
  refresh();
}

void ForwardChain::refresh() {
  std::vector<Active> fresh;
  for (const Effect* e : effect_registry()) {
    if (!values_.active(*e)) continue;
    const Values v = values_.of(*e);
    Active a{e, std::vector<double>(v.begin(), v.end()), MotionState{}};
    // Keep the state of a motion effect that stays active.
    for (const Active& old : active_) {
      if (old.effect == e) a.state = old.state;
    }
    fresh.push_back(std::move(a));
  }
  active_ = std::move(fresh);
  time_shift_ = 0.0;
  drive_offset_ = 0.0;
  timing_ = ChannelTiming{};
  converter_ = ConverterSpec{};
  impairments_ = Impairments{};
  for (const Active& a : active_) {
    time_shift_ += a.effect->resolver_time_shift(a.values);
    drive_offset_ += a.effect->drive_frame_offset(a.values);
    a.effect->channel_timing(a.values, timing_);
    a.effect->converter(a.values, converter_);
    a.effect->impairments(a.values, impairments_);
  }
}

void ForwardChain::set_value(const Effect& effect, std::size_t param, double value) {
  values_.set(effect.name(), effect.params()[param].name, value);
  refresh();
}

double ForwardChain::resolver_angle(double theta_m, double omega_m, bool commit) {
  double seen = theta_m;
  double shift = 0.0;
  for (Active& a : active_) {
    seen = a.effect->seen_mech_angle(a.values, seen, omega_m, a.state, commit);
    shift += a.effect->resolver_angle_shift(a.values, p_r_, p_);
  }
  return static_cast<double>(p_r_) * seen + shift;
}

SinCos ForwardChain::envelopes(double theta, double t) const {
  SinCos env = ideal_envelopes(theta);
  for (WindingStage stage : {WindingStage::kFundamental, WindingStage::kAdditive, WindingStage::kGain,
                             WindingStage::kOffset}) {
    for (const Active& a : active_) a.effect->windings_in_time(a.values, stage, theta, t, env);
  }
  return env;
}

PhaseCurrents ForwardChain::machine_currents(double i_d_cmd, double i_q_cmd, double theta_e) const {
  PhaseCurrents i = ideal_phase_currents(i_d_cmd, i_q_cmd, theta_e + drive_offset_);
  for (const Active& a : active_) a.effect->currents(a.values, CurrentStage::kInverter, theta_e, i);
  return i;
}

PhaseCurrents ForwardChain::measured_currents(const PhaseCurrents& actual, double theta_e) const {
  PhaseCurrents i = actual;
  for (CurrentStage stage : {CurrentStage::kSensorGain, CurrentStage::kSensorOffset}) {
    for (const Active& a : active_) a.effect->currents(a.values, stage, theta_e, i);
  }
  return i;
}

}  // namespace resolver
