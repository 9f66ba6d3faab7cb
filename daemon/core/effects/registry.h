// The effect registry: every effect of the sensor chain, one line each in
// registry.cpp. The catalog table (--list-effects), the spec parser
// (chain_values.h), the simulator's forward chain (forward_chain.h), truth files,
// discovery's candidates and docs/EFFECTS.md all come from this list.
//
// Adding an effect: one file pair in this folder (an Effect subclass, see
// effect.h; the library takes every .cpp here), one line in registry.cpp (and its
// #include), one hidden-effect row in tests/hidden_effect/matrix.py (the ctest
// cases are read from it). The registry's consistency tests then ask, on purpose,
// for what no code can decide: the names in registry_test's stable_names() (they
// become interface), the signals it reaches in sim_effects_test's table,
// docs/EFFECTS.md regenerated (resolver-sim --effects-markdown) and its row in
// docs/ARCHITECTURE.md section 7; the matrix also runs the independent generator
// (tests/independent/benchgen), which learns the effect from that row's physics.
// Effect and parameter names are part of the project's interface (CLI, TOML,
// truth files, reports, scripts): keep them stable.
#pragma once

#include <span>
#include <string>
#include <string_view>

#include "daemon/core/effects/effect.h"

namespace resolver {

/// Every effect, in catalog order (docs/ARCHITECTURE.md §7). Cannot fail.
[[nodiscard]] std::span<const Effect* const> effect_registry();

/// The effect called `name`, or nullptr.
[[nodiscard]] const Effect* find_effect(std::string_view name);

/// Position of `effect` in effect_registry(). The effect must be registered.
[[nodiscard]] std::size_t registry_index(const Effect& effect);

/// Index of the parameter `param` of `effect`, or -1.
[[nodiscard]] int find_param(const Effect& effect, std::string_view param);

/// "a, b, c": the names of the effects (fittable ones only if asked).
[[nodiscard]] std::string effect_names(bool fittable_only);

/// "p1, p2": the listed parameters of an effect (all of them if `all`).
[[nodiscard]] std::string parameter_names(const Effect& effect, bool all);

/// The catalog as a human-readable table for --list-effects and --help.
[[nodiscard]] std::string format_effect_catalog();

/// The catalog as Markdown (docs/EFFECTS.md is generated from it).
[[nodiscard]] std::string effects_markdown();

}  // namespace resolver
