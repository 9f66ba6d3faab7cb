// The parameter values of every effect in the chain: what the simulator runs
// and truth files record. Defaults are each parameter's neutral value (the
// ideal chain); a spec "effect:param=value,..." changes some of them.
//
// Spec grammar:  effect:param=value[,param=value...]
//   e.g. "amplitude_imbalance:alpha=0.003", "offsets:o_s=0.001,o_c=-0.002",
//        "tracking_loop:omega_n=3000,zeta=0.7", "harmonics:k3=5e-4,k3_opp=2e-4",
//        "delay:d=2e-3", "backlash:h=0.01", "mechanical_harmonics:a2=1e-4"
#pragma once

#include <span>
#include <string_view>
#include <utility>
#include <vector>

#include "daemon/core/effects/registry.h"

namespace resolver {

class ChainValues {
 public:
  /// Every effect at its neutral values.
  ChainValues();

  /// The values of `effect` in its params() order.
  [[nodiscard]] Values of(const Effect& effect) const { return values_[registry_index(effect)]; }
  /// One value. Throws std::invalid_argument naming the unknown effect or parameter.
  [[nodiscard]] double get(std::string_view effect, std::string_view param) const;
  /// Sets one value after checking its range. Throws std::invalid_argument naming
  /// the effect, parameter, value and the valid range; the chain is unchanged then.
  void set(std::string_view effect, std::string_view param, double value);
  /// True when `effect` changes the chain from ideal.
  [[nodiscard]] bool active(const Effect& effect) const { return effect.active(of(effect)); }

  /// Applies one spec ("effect:param=value,..."). Throws std::invalid_argument
  /// naming the bad effect / parameter / value and listing the valid ones; the
  /// chain is unchanged then.
  void apply_spec(std::string_view spec);
  /// Checks every active effect's whole parameter set (Effect::validate). Throws.
  void validate() const;

  /// An active effect and its parameter values (for truth files and reports).
  struct ActiveEffect {
    const Effect* effect = nullptr;
    std::vector<std::pair<std::string_view, double>> parameters;  ///< non-neutral ones, all for 1-parameter effects
  };
  /// The active effects in registry order.
  [[nodiscard]] std::vector<ActiveEffect> active_effects() const;

 private:
  std::vector<std::vector<double>> values_;  ///< by registry index
};

}  // namespace resolver
