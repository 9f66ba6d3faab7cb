// Effects users add without recompiling: [[model.custom]] blocks in the TOML.
//
//   [[model.custom]]
//   name = "slow_drift"                 # how [model] effects / --effects name it
//   signal = "position_error"           # position_error | rd_angle | sin | cos | i_d | i_q
//   terms = ["t", "t*sin(2*theta)"]     # one coefficient each: c1, c2, ...
//   description = "alpha warming up"   # optional
//
// Each term is an expression (muparser, Debian libmuparser-dev) of
//   theta    true resolver electrical angle [rad]     theta_m  true mechanical angle [rad]
//   theta_e  true motor electrical angle [rad]        omega    resolver electrical speed [rad/s]
//   t        time from the log's first sample [s]     and sign(omega), abs(), sin(), ...
// The effect adds c_i x term_i to its signal:
//   position_error  the angle the resolver sees is off by -sum c_i term_i, so both the R/D
//                   angle's and the sin/cos angle's error gain sum c_i term_i [rad] (compensated)
//   rd_angle        only the R/D angle's error (a converter-side error) [rad] (compensated)
//   sin, cos        the envelope gains sum c_i term_i [fraction of amplitude]
//   i_d, i_q        the dq current gains sum c_i term_i [A]
// A custom effect is fitted, ranked, compensated (position-error terms), persisted,
// exported and plotted like a catalog effect. Errors name the block, the term and the
// column of the expression.
#pragma once

#include <memory>
#include <mutex>
#include <string>
#include <string_view>
#include <vector>

#include "daemon/core/effects/effect.h"

namespace mu {
class Parser;
}

namespace resolver {

/// One [[model.custom]] block as written.
struct CustomEffectSpec {
  std::string name;
  std::string signal = "position_error";
  std::vector<std::string> terms;
  std::string description;
  std::string origin;  ///< where it was written, for messages ("resolverd.toml [[model.custom]] #2")
};

enum class CustomSignal : std::uint8_t { kPositionError, kRdAngle, kSin, kCos, kId, kIq };

class CustomEffect final : public Effect {
 public:
  /// Compiles the terms. Throws std::invalid_argument naming the block (origin and
  /// name), the term and the column of the expression, or the bad signal / name.
  explicit CustomEffect(CustomEffectSpec spec);
  ~CustomEffect() override;
  CustomEffect(const CustomEffect&) = delete;
  CustomEffect& operator=(const CustomEffect&) = delete;
  CustomEffect(CustomEffect&&) = delete;
  CustomEffect& operator=(CustomEffect&&) = delete;

  [[nodiscard]] std::string_view name() const override { return spec_.name; }
  [[nodiscard]] std::string_view description() const override { return description_; }
  [[nodiscard]] std::string_view source() const override { return spec_.origin; }
  [[nodiscard]] std::string_view physics() const override { return physics_; }
  [[nodiscard]] std::span<const ParamInfo> params() const override { return params_; }
  [[nodiscard]] EffectStage stage() const override;
  [[nodiscard]] bool needs_reference() const override { return needs_reference_; }
  [[nodiscard]] const CustomEffectSpec& spec() const { return spec_; }
  [[nodiscard]] CustomSignal signal() const { return signal_; }
  /// True for position-error terms: the compensation removes them.
  [[nodiscard]] bool compensable() const;

  void signature(const SignatureRow& row, const AngleBasis& basis, Values v, SignatureColumns& out) const override;
  /// Term `i`'s value at `row` (nan when muparser fails there).
  [[nodiscard]] double term_value(std::size_t i, const SignatureRow& row) const;
  [[nodiscard]] std::size_t term_count() const { return parsers_.size(); }

 private:
  /// The parser variables from a row (the caller holds mutex_).
  void bind(const SignatureRow& row) const;
  /// Term i at the bound variables; NaN where the parser fails (the caller holds mutex_).
  [[nodiscard]] double evaluate(std::size_t i) const;
  /// Throws std::invalid_argument naming term `i` when it is not finite anywhere.
  void check_finite_somewhere(mu::Parser& p, std::size_t i);

  CustomEffectSpec spec_;
  CustomSignal signal_ = CustomSignal::kPositionError;
  std::string description_, physics_;
  std::vector<std::string> param_names_;
  std::vector<ParamInfo> params_;
  bool needs_reference_ = false;
  // The parsers read their variables from these; one evaluation at a time (the
  // live fit's thread and the compensation may share a model).
  mutable std::mutex mutex_;
  mutable double theta_ = 0.0, theta_m_ = 0.0, theta_e_ = 0.0, omega_ = 0.0, t_ = 0.0;
  std::vector<std::unique_ptr<mu::Parser>> parsers_;
};

/// The custom effects of one config, owned together; models refer to them by name.
class CustomEffects {
 public:
  CustomEffects() = default;
  /// Compiles every block. Throws std::invalid_argument (see CustomEffect), also for
  /// a name that is used twice or that a catalog effect already has.
  explicit CustomEffects(const std::vector<CustomEffectSpec>& specs);
  [[nodiscard]] const CustomEffect* find(std::string_view name) const;
  [[nodiscard]] const std::vector<std::unique_ptr<CustomEffect>>& all() const { return effects_; }
  [[nodiscard]] bool empty() const { return effects_.empty(); }

 private:
  std::vector<std::unique_ptr<CustomEffect>> effects_;
};

}  // namespace resolver
