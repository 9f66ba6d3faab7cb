#include "daemon/core/effects/channel_delay.h"

#include <array>

#include "daemon/core/effects/effect.h"
#include "daemon/core/effects/param_set.h"

namespace resolver {
namespace {

constexpr std::array kParams{
    ParamInfo{.name = "tau", .unit = "[s]",
              .description = "delay of the analog cos path against sin, before the converter", .min = -1e-3,
              .max = 1e-3},
};
/// Typed, named access to the values of kParams (param_set.h).
using ChannelDelayParams = ParamSet<kParams>;

class ChannelDelayEffect final : public BasicEffect {
 public:
  ChannelDelayEffect()
      : BasicEffect({"channel_delay",
                     "cos path delayed tau before the R/D converter: quadrature beta = -omega tau on the R/D angle "
                     "and the sin/cos; eps ~ (omega tau/2)(1 - cos 2theta)",
                     "channel_delay.h (Hanselman eq. 6-7 with beta = -omega tau)",
                     "the cos channel's analog path lags the sin channel's: a quadrature error that grows with speed "
                     "and that the R/D angle and the sin/cos signals both show"},
                    kParams, EffectStage::kChannels) {}
  [[nodiscard]] bool needs_speed_change() const override { return true; }
  void channel_timing(Values v, ChannelTiming& timing) const override {
    const double tau = ChannelDelayParams(v)["tau"];
    timing.converter_cos_dt -= tau;
    timing.dsp_cos_dt -= tau;
  }
  void signature(const SignatureRow& row, const AngleBasis& b, Values /*v*/, SignatureColumns& out) const override {
    out.col(ChannelDelayParams::index("tau")) =
        envelope_column(b, 0.5 * row.omega * (1.0 - b.rd_cos(2)), 0.0, row.omega * b.env_sin(1));
  }
};

}  // namespace

const Effect& channel_delay_effect() {
  static const ChannelDelayEffect effect;
  return effect;
}

}  // namespace resolver
