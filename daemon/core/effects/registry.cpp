#include "daemon/core/effects/registry.h"

#include <vector>
#include <stdexcept>

#include <fmt/format.h>

#include "daemon/core/effects/amplitude_imbalance.h"
#include "daemon/core/effects/backlash.h"
#include "daemon/core/effects/channel_delay.h"
#include "daemon/core/effects/current_gain_mismatch.h"
#include "daemon/core/effects/current_offsets.h"
#include "daemon/core/effects/dead_time.h"
#include "daemon/core/effects/delay.h"
#include "daemon/core/effects/eccentricity.h"
#include "daemon/core/effects/envelope_drift.h"
#include "daemon/core/effects/harmonics.h"
#include "daemon/core/effects/mechanical_harmonics.h"
#include "daemon/core/effects/mounting_offset.h"
#include "daemon/core/effects/noise.h"
#include "daemon/core/effects/offsets.h"
#include "daemon/core/effects/quadrature.h"
#include "daemon/core/effects/quantization.h"
#include "daemon/core/effects/sampling_skew.h"
#include "daemon/core/effects/tracking_loop.h"

namespace resolver {

namespace {

const std::vector<const Effect*>& registry() {
  // One line per effect. The order is the catalog's (docs/ARCHITECTURE.md section 7: resolver side
  // first; converter; motion against the reference; currents; impairments) and
  // the forward chain's within a stage: the play (backlash) acts on the shaft
  // before the resolver's own geometry (eccentricity, mechanical harmonics).
  static const std::vector<const Effect*> effects{
      &amplitude_imbalance_effect(),
      &quadrature_effect(),
      &offsets_effect(),
      &harmonics_effect(),
      &envelope_drift_effect(),
      &sampling_skew_effect(),
      &channel_delay_effect(),
      &tracking_loop_effect(),
      &quantization_effect(),
      &backlash_effect(),
      &eccentricity_effect(),
      &mechanical_harmonics_effect(),
      &mounting_offset_effect(),
      &delay_effect(),
      &current_offsets_effect(),
      &current_gain_mismatch_effect(),
      &dead_time_effect(),
      &noise_effect(),
      &outliers_effect(),
      &current_outliers_effect(),
  };
  return effects;
}

std::string_view stage_name(EffectStage s) {
  switch (s) {
    case EffectStage::kMotion: return "motion";
    case EffectStage::kWindings: return "windings";
    case EffectStage::kChannels: return "channels";
    case EffectStage::kConverter: return "converter";
    case EffectStage::kCurrents: return "currents";
    case EffectStage::kNoise: return "noise";
  }
  return "?";
}

std::string needs(const Effect& e) {
  std::string out;
  auto add = [&](std::string_view s) { out += (out.empty() ? "" : ", ") + std::string(s); };
  if (!e.fittable()) add("not fitted (sets the floor)");
  if (e.needs_reference()) add("needs the reference angle");
  if (e.current_side()) add("needs the phase currents");
  if (e.needs_speed_change()) add("told from others only over speed changes or reversals");
  return out;
}

}  // namespace

std::span<const Effect* const> effect_registry() { return registry(); }

const Effect* find_effect(std::string_view name) {
  for (const Effect* e : registry()) {
    if (e->name() == name) return e;
  }
  return nullptr;
}

std::size_t registry_index(const Effect& effect) {
  const auto& r = registry();
  for (std::size_t i = 0; i < r.size(); ++i) {
    if (r[i] == &effect) return i;
  }
  throw std::invalid_argument(fmt::format("effect '{}' is not in the registry", effect.name()));
}

int find_param(const Effect& effect, std::string_view param) {
  const auto ps = effect.params();
  for (std::size_t i = 0; i < ps.size(); ++i) {
    if (ps[i].name == param) return static_cast<int>(i);
  }
  return -1;
}

std::string effect_names(bool fittable_only) {
  std::string out;
  for (const Effect* e : registry()) {
    if (fittable_only && !e->fittable()) continue;
    out += (out.empty() ? "" : ", ") + std::string(e->name());
  }
  return out;
}

std::string parameter_names(const Effect& effect, bool all) {
  std::string out;
  std::size_t hidden = 0;
  for (const ParamInfo& p : effect.params()) {
    if (!all && !p.listed) {
      ++hidden;
      continue;
    }
    out += (out.empty() ? "" : ", ") + std::string(p.name);
  }
  if (hidden > 0) out += fmt::format(" (and {} more: --list-effects)", hidden);
  return out;
}

std::string format_effect_catalog() {
  std::string out =
      "Effect catalog. Spec: effect:param=value[,param=value...]; in a model, effect or effect(param,param,...)\n";
  for (const Effect* e : registry()) {
    out += fmt::format("\n  {:<22}{}\n  {:<22}stage: {}; source: {}\n", e->name(), e->description(), "",
                       stage_name(e->stage()), e->source());
    if (const std::string n = needs(*e); !n.empty()) out += fmt::format("  {:<22}{}\n", "", n);
    std::size_t hidden = 0;
    for (const ParamInfo& p : e->params()) {
      if (!p.listed) {
        ++hidden;
        continue;
      }
      out += fmt::format("      {:<9}{:<26}{}, in [{}, {}]{}\n", p.name, p.unit, p.description, p.min, p.max,
                         p.nonlinear ? " (nonlinear)" : "");
    }
    if (hidden > 0) out += fmt::format("      ... and {} more parameters of the same kind\n", hidden);
  }
  return out;
}

std::string effects_markdown() {
  std::string out =
      "# Effect catalog\n\n"
      "Generated from the effect registry (`daemon/core/effects/registry.cpp`) by `resolver-sim "
      "--effects-markdown`; do not edit by hand. Conventions: eps = theta_true - theta_measured, "
      "theta = p_r theta_m (docs/ARCHITECTURE.md section 3).\n\n"
      "Spec (resolver-sim `--effect`): `effect:param=value[,param=value...]`. Model (`--effects`, `[model] "
      "effects`): `effect` (its default parameters) or `effect(param,param,...)`.\n";
  for (const Effect* e : registry()) {
    out += fmt::format("\n## `{}`\n\n{}\n\n- stage: {}\n- source: {}\n- physics: {}\n", e->name(), e->description(),
                       stage_name(e->stage()), e->source(), e->physics());
    if (const std::string n = needs(*e); !n.empty()) out += fmt::format("- {}\n", n);
    out += "\n| parameter | unit | range | meaning | fitted by default |\n|---|---|---|---|---|\n";
    for (const ParamInfo& p : e->params()) {
      out += fmt::format("| `{}` | {} | [{}, {}] | {}{} | {} |\n", p.name, p.unit, p.min, p.max, p.description,
                         p.nonlinear ? " (nonlinear)" : "", e->fittable() && p.default_fit ? "yes" : "no");
    }
  }
  return out;
}

}  // namespace resolver
