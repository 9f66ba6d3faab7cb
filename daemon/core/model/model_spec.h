// Which effects a model has, and which of their parameters it fits.
//
// A model is named by effect references (config `[model] effects`, CLI
// `--effects`):   effect            the effect with its default parameters
//                 effect(p1,p2,..)  the effect with exactly these parameters
// e.g. "amplitude_imbalance", "harmonics(k3,k5_opp)", "tracking_loop(omega_n,zeta)",
// "mechanical_harmonics(a2,b2)". Parameters a model does not fit stay at their
// neutral values. A comma-separated list splits only outside parentheses:
// "amplitude_imbalance,harmonics(k3,k5),delay".
#pragma once

#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "daemon/core/effects/effect.h"

namespace resolver {

class CustomEffects;

/// One effect of a model and the parameters it fits.
struct ModelTerm {
  const Effect* effect = nullptr;
  std::vector<int> params;  ///< indices into effect->params(), ascending
  /// The reference that names exactly this term: "effect" when the parameters are
  /// the effect's defaults, else "effect(p1,p2)".
  [[nodiscard]] std::string reference() const;
  /// "effect.param" of the term's i-th fitted parameter.
  [[nodiscard]] std::string param_name(std::size_t i) const;
};

struct ModelSpec {
  std::vector<ModelTerm> terms;

  /// Parses references (each may itself be a comma-separated list). Throws
  /// std::invalid_argument naming the reference, the unknown effect or parameter
  /// and the valid ones, or an effect that only sets the floor (noise,
  /// quantization, outliers). `customs` (may be null) resolves user effects.
  [[nodiscard]] static ModelSpec parse(std::span<const std::string> references, const CustomEffects* customs = nullptr);
  /// The registry parameters among `names` ("effect.param"; any other name is
  /// skipped), each fitted: a calibration file's parameter list as a model (files
  /// written before the model's references were saved with it). Cannot fail.
  [[nodiscard]] static ModelSpec for_parameters(std::span<const std::string> names);
  /// The references, one per term.
  [[nodiscard]] std::vector<std::string> references() const;
  /// The term of `effect`, or nullptr.
  [[nodiscard]] const ModelTerm* find(const Effect& effect) const;
  /// Adds a term (its parameters merged into an existing term of the same effect).
  void add(const ModelTerm& term);
  /// Number of fitted parameters.
  [[nodiscard]] std::size_t parameter_count() const;
};

/// Splits "a,b(c,d),e" at the commas outside parentheses; trims blanks; drops empties.
[[nodiscard]] std::vector<std::string> split_effect_list(std::string_view text);

/// The candidate closest to `name` for a "did you mean" hint, or "" when none is
/// close enough to be a typo: the edit distance (insert, delete, replace, swap two
/// neighbours; case ignored) is at most a third of the name's length, at most 3 and
/// at least 1 ("amplitude_imbalanse" -> "amplitude_imbalance", "nope" -> ""). Ties go
/// to the first candidate. Cannot fail.
[[nodiscard]] std::string closest_name(std::string_view name, std::span<const std::string> candidates);

/// The default parameters of an effect (ParamInfo::default_fit), as indices.
[[nodiscard]] std::vector<int> default_params(const Effect& effect);

}  // namespace resolver
