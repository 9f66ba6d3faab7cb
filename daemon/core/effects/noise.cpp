#include "daemon/core/effects/noise.h"

#include <array>

#include "daemon/core/effects/effect.h"

namespace resolver {

double gaussian_noise(NoiseEngine& engine, double sigma) {
  if (sigma == 0.0) return 0.0;
  // A fresh distribution per draw: no cached second value hides in a member, so
  // the sequence depends only on the engine state.
  std::normal_distribution<double> dist(0.0, sigma);
  return dist(engine);
}

// ---- registry unit ------------------------------------------------------------
namespace {

class NoiseEffect final : public BasicEffect {
 public:
  NoiseEffect()
      : BasicEffect({"noise", "white noise on sin/cos samples and phase currents; sets the floor", "docs/ARCHITECTURE.md section 7",
                     "measurement noise: the floor every residual is compared with"},
                    kNoiseParams, EffectStage::kNoise) {}
  [[nodiscard]] bool fittable() const override { return false; }
  void impairments(Values v, Impairments& imp) const override {
    const NoiseParams p(v);
    imp.sigma_sc += p["sigma_sc"];
    imp.sigma_i += p["sigma_i"];
  }
};

constexpr std::array kOutlierParams{
    ParamInfo{.name = "rate", .unit = "[1/s]", .description = "impulsive samples (EMI spikes) on the sin channel",
              .min = 0.0, .max = 1e5},
    ParamInfo{.name = "size", .unit = "[counts]", .description = "size of each spike (random sign)", .min = 0.0,
              .max = 65535.0},
};
using OutlierParams = ParamSet<kOutlierParams>;

class OutliersEffect final : public BasicEffect {
 public:
  OutliersEffect()
      : BasicEffect({"outliers", "impulsive samples on the sin channel (EMI, bit errors): never part of a model",
                     "issue 14", "impulsive samples: found by a robust test and kept out of the fit"},
                    kOutlierParams, EffectStage::kNoise) {}
  [[nodiscard]] bool fittable() const override { return false; }
  void impairments(Values v, Impairments& imp) const override {
    const OutlierParams p(v);
    imp.outlier_rate += p["rate"];
    imp.outlier_size = p["size"];
  }
};

constexpr std::array kCurrentOutlierParams{
    ParamInfo{.name = "rate", .unit = "[1/s]", .description = "impulsive samples (EMI spikes) on phase current a",
              .min = 0.0, .max = 1e5},
    ParamInfo{.name = "size", .unit = "[A]", .description = "size of each spike", .min = 0.0, .max = 1000.0},
    ParamInfo{.name = "positive", .unit = "[1]",
              .description = "share of spikes that are positive (0.5: random sign; 1: an ADC that glitches high)",
              .min = 0.0, .max = 1.0, .neutral = 0.5},
};
using CurrentOutlierParams = ParamSet<kCurrentOutlierParams>;

/// The currents' spikes: an inverter's switching edges coupling into one phase current
/// sensor's ADC. One-sided spikes (a glitch that reads high) do not average out: a fit that
/// took them in would shift the currents' operating point by rate x size / sample rate.
class CurrentOutliersEffect final : public BasicEffect {
 public:
  CurrentOutliersEffect()
      : BasicEffect({"current_outliers",
                     "impulsive samples on phase current a (switching EMI on its ADC): never part of a model",
                     "docs/ARCHITECTURE.md section 7",
                     "impulsive samples: found by a robust test on i_d, i_q and kept out of the fit"},
                    kCurrentOutlierParams, EffectStage::kNoise) {}
  [[nodiscard]] bool fittable() const override { return false; }
  void impairments(Values v, Impairments& imp) const override {
    const CurrentOutlierParams p(v);
    imp.current_outlier_rate += p["rate"];
    imp.current_outlier_size = p["size"];
    imp.current_outlier_positive = p["positive"];
  }
};

}  // namespace

const Effect& noise_effect() {
  static const NoiseEffect effect;
  return effect;
}

const Effect& outliers_effect() {
  static const OutliersEffect effect;
  return effect;
}

const Effect& current_outliers_effect() {
  static const CurrentOutliersEffect effect;
  return effect;
}

}  // namespace resolver
