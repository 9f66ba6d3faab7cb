// Effect: measurement noise on the sampled sin/cos envelopes and phase currents.
//
// White Gaussian noise added by the inverter's ADCs; it sets the floor every
// estimate and residual is compared against (docs/ARCHITECTURE.md §7). It is applied where the
// DSP samples (ADC counts, amperes), not inside the R/D converter's analog loop.
//
// Randomness only through an engine the caller passes in (no global state), so a
// seed reproduces a run exactly (with the same standard library build: the
// normal distribution's algorithm is implementation-defined).
#pragma once

#include <array>
#include <cstdint>
#include <random>

#include "daemon/core/effects/param_set.h"

namespace resolver {

/// The effect's parameters, listed once (param_set.h).
inline constexpr std::array kNoiseParams{
    ParamInfo{.name = "sigma_sc", .unit = "[counts]", .description = "white noise on each sin/cos ADC sample",
              .min = 0.0, .max = 32767.0},
    ParamInfo{.name = "sigma_i", .unit = "[A]", .description = "white noise on each phase current sample",
              .min = 0.0, .max = 1000.0},
};
using NoiseParams = ParamSet<kNoiseParams>;

/// The one random engine type of the effect models.
using NoiseEngine = std::mt19937_64;

/// One N(0, sigma^2) draw [unit of sigma]. Returns exactly 0 and leaves the engine
/// untouched when sigma == 0, so switching one noise source off does not change
/// the draws of the others.
[[nodiscard]] double gaussian_noise(NoiseEngine& engine, double sigma);

/// The registry unit of this effect (registry.h).
class Effect;
[[nodiscard]] const Effect& noise_effect();
/// Impulsive samples (EMI spikes, bit errors): a simulator impairment the fit must keep out.
[[nodiscard]] const Effect& outliers_effect();
/// The same on phase current a (switching EMI on a current sensor's ADC).
[[nodiscard]] const Effect& current_outliers_effect();

}  // namespace resolver
