#include "daemon/core/effects/effect.h"

#include <vector>

namespace resolver {

bool Effect::active(Values v) const {
  const auto ps = params();
  for (std::size_t i = 0; i < ps.size() && i < v.size(); ++i) {
    if (v[i] != ps[i].neutral) return true;
  }
  return false;
}

HarmonicOrders Effect::orders(std::span<const int> /*params*/) const {
  switch (stage()) {
    case EffectStage::kWindings:
    case EffectStage::kChannels:
    case EffectStage::kConverter: return {.theta = 2};
    case EffectStage::kCurrents: return {.theta_e = 1};
    case EffectStage::kMotion:
    case EffectStage::kNoise: return {};
  }
  return {};
}

void Effect::signature(const SignatureRow& /*row*/, const AngleBasis& /*basis*/, Values /*v*/,
                       SignatureColumns& out) const {
  out.clear();  // effects without a signature (noise, quantization) change no fitted signal
}

void Effect::contribution(const SignatureRow& row, const AngleBasis& basis, Values v, SignalValues& out) const {
  std::vector<SignalValues> storage(v.size());
  SignatureColumns cols(storage);
  signature(row, basis, v, cols);
  for (std::size_t i = 0; i < v.size(); ++i) {
    const SignalValues& c = cols.col(i);
    out.rd += c.rd * v[i];
    out.sa += c.sa * v[i];
    out.sr += c.sr * v[i];
    out.d += c.d * v[i];
    out.q += c.q * v[i];
  }
}

}  // namespace resolver
