// Typed, named access to an effect's parameters, generated from its one ParamInfo
// list (issue 22: "no struct beside it, no positional reads").
//
// An effect writes each parameter once, in a constexpr list in its header:
//     inline constexpr std::array kQuadratureParams{ParamInfo{.name = "beta", .unit = "[rad]", ...}};
//     using QuadratureParams = ParamSet<kQuadratureParams>;
// and everything that reads or writes a value names it:
//     const QuadratureParams p{{"beta", 0.01}};  // the others at their neutral values
//     std::cos(theta + p["beta"]);
// The name is looked up in the list when the program compiles (ParamKey's consteval
// constructor), so a misspelt name, or one the list lacks, does not compile, and no
// field, index or range beside the list can drift from it. ParamSet holds the values
// in the list's order, which is also how the registry hands them to an effect's
// hooks (Values): ParamSet(v) takes those, values() gives them back.
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <initializer_list>
#include <stdexcept>
#include <string>
#include <string_view>

#include "daemon/core/effects/param_info.h"

namespace resolver {

/// A parameter of the list `List`, named at compile time: the only way to index a
/// ParamSet. Implicit from a string literal on purpose, so p["beta"] reads as a name.
template <const auto& List>
class ParamKey {
 public:
  consteval ParamKey(const char* name) : index_(param_index(List, name)) {}
  /// For names built at compile time (harmonics' k2..k20 from their order).
  consteval explicit ParamKey(std::string_view name) : index_(param_index(List, name)) {}

  /// The parameter's place in the list (and in Values, and in the signature's columns).
  [[nodiscard]] constexpr std::size_t index() const { return index_; }
  [[nodiscard]] constexpr const ParamInfo& info() const { return List[index_]; }
  [[nodiscard]] constexpr bool operator==(const ParamKey&) const = default;

 private:
  std::size_t index_;
};

/// One value per parameter of `List`, read and written by name (see the header comment).
template <const auto& List>
class ParamSet {
 public:
  using Key = ParamKey<List>;
  static constexpr std::size_t kSize = List.size();

  /// A name and its value, for the named constructor.
  struct Named {
    Key key;
    double value;
  };

  /// Every parameter at its neutral value: the effect does nothing.
  constexpr ParamSet() {
    for (std::size_t i = 0; i < kSize; ++i) values_[i] = List[i].neutral;
  }
  /// The named values, the others neutral: QuadratureParams{{"beta", 0.01}}.
  constexpr ParamSet(std::initializer_list<Named> named) : ParamSet() {
    for (const Named& n : named) values_[n.key.index()] = n.value;
  }
  /// The values a registry hook receives, in the list's order. Throws
  /// std::invalid_argument when `v` does not have one value per parameter (a caller
  /// that mixed up effects: the registry always passes the whole list).
  explicit ParamSet(Values v) {
    if (v.size() != kSize) {
      throw std::invalid_argument("ParamSet: " + std::to_string(v.size()) + " values for the " +
                                  std::to_string(kSize) + " parameters starting with '" + std::string(List[0].name) +
                                  "'");
    }
    std::copy(v.begin(), v.end(), values_.begin());
  }

  [[nodiscard]] constexpr double operator[](Key k) const { return values_[k.index()]; }
  [[nodiscard]] constexpr double& operator[](Key k) { return values_[k.index()]; }

  /// The place of a parameter in the list: its column in the effect's signature
  /// (SignatureColumns::col) and its slot in Values.
  [[nodiscard]] static constexpr std::size_t index(Key k) { return k.index(); }
  /// The list entry of a parameter (its range, unit, neutral value).
  [[nodiscard]] static constexpr const ParamInfo& info(Key k) { return k.info(); }
  /// The list itself.
  [[nodiscard]] static constexpr const auto& list() { return List; }

  /// True when a parameter is away from its neutral value (the default rule of
  /// Effect::active; an effect with another rule says so beside its hooks).
  [[nodiscard]] constexpr bool active() const {
    for (std::size_t i = 0; i < kSize; ++i) {
      if (values_[i] != List[i].neutral) return true;
    }
    return false;
  }

  /// The values in the list's order, as the registry and ChainValues keep them.
  [[nodiscard]] Values values() const { return values_; }

 private:
  std::array<double, kSize> values_{};
};

}  // namespace resolver
