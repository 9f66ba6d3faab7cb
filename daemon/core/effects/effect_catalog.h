// The effect catalog (DESIGN 6) as data: each effect's name, parameters with
// units and valid ranges, a one-line description and the paper equation it comes
// from, plus the spec parser used by resolver-sim --effect and the config files.
//
// Effect and parameter names are part of the project's interface (CLI, TOML,
// truth files, reports): keep them stable. A new effect slots in as one small
// unit (header + source with params, forward model, signature), a member of
// SensorChainConfig, and one row here with implemented = true.
//
// Spec grammar:  effect:param=value[,param=value...]
//   e.g. "amplitude_imbalance:alpha=0.003", "offsets:o_s=0.001,o_c=-0.002",
//        "tracking_loop:omega_n=3000,zeta=0.7", "harmonics:k0=0.001,k3=0.0005",
//        "sampling_skew:tau=2e-6", "eccentricity:e=5e-4,phase=1", "mounting_offset:theta_0=0.05",
//        "current_offsets:off_a=0.05,off_b=-0.03", "current_gain_mismatch:gain_a=0.01",
//        "dead_time:t_d=2e-6"
#pragma once

#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "daemon/core/effects/sensor_chain.h"

namespace resolver {

struct EffectParameter {
  std::string_view name;
  std::string_view unit;         ///< e.g. "[rad]", "[1]"
  std::string_view description;  ///< one line
  double min;                    ///< smallest accepted value (inclusive)
  double max;                    ///< largest accepted value (inclusive)
  bool integer;                  ///< value must be a whole number
  bool listed;                   ///< shown by format_effect_catalog (false for k6..k16)
  /// Writes / reads the parameter in a SensorChainConfig; nullptr while the effect
  /// is not implemented.
  void (*set)(SensorChainConfig&, double);
  double (*get)(const SensorChainConfig&);
};

struct EffectInfo {
  std::string_view name;
  std::string_view description;  ///< one line: forward model and signature
  std::string_view source;       ///< paper equations
  std::span<const EffectParameter> parameters;
  bool implemented;
  /// True when the effect changes the chain from ideal; nullptr while not implemented.
  bool (*active)(const SensorChainConfig&);
};

/// Every catalog effect in DESIGN 6 order, implemented or not. Cannot fail.
[[nodiscard]] std::span<const EffectInfo> effect_catalog();

/// The catalog row of `name`, or nullptr.
[[nodiscard]] const EffectInfo* find_effect(std::string_view name);

/// Applies one spec ("effect:param=value,...") to `config`. Returns std::nullopt
/// on success; otherwise `config` is left unchanged and the message names the bad
/// effect / parameter / value and lists the valid ones.
[[nodiscard]] std::optional<std::string> apply_effect_spec(SensorChainConfig& config, std::string_view spec);

/// The catalog as a human-readable table for --list-effects and --help.
[[nodiscard]] std::string format_effect_catalog();

/// An active effect and its parameter values (for truth files and reports).
struct EffectValues {
  std::string_view effect;
  std::vector<std::pair<std::string_view, double>> parameters;
};

/// The effects of `config` that are active, with all their parameter values
/// (harmonics: only non-zero orders). Catalog order.
[[nodiscard]] std::vector<EffectValues> active_effect_values(const SensorChainConfig& config);

}  // namespace resolver
