#include "daemon/core/effects/chain_values.h"

#include <charconv>
#include <cmath>
#include <stdexcept>
#include <string>
#include <system_error>

#include <fmt/format.h>

namespace resolver {

namespace {

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  return s;
}

const Effect& require_effect(std::string_view name, std::string_view context) {
  const Effect* e = find_effect(name);
  if (e == nullptr) {
    throw std::invalid_argument(fmt::format("{}unknown effect '{}'; valid effects: {} (see --list-effects)", context,
                                            name, effect_names(false)));
  }
  return *e;
}

int require_param(const Effect& e, std::string_view param, std::string_view context) {
  const int i = find_param(e, param);
  if (i < 0) {
    throw std::invalid_argument(fmt::format("{}effect '{}' has no parameter '{}'; valid parameters: {}", context,
                                            e.name(), param, parameter_names(e, true)));
  }
  return i;
}

void check_range(const Effect& e, const ParamInfo& p, double value, std::string_view context) {
  if (!std::isfinite(value) || value < p.min || value > p.max || (p.integer && value != std::round(value))) {
    throw std::invalid_argument(fmt::format("{}parameter '{}' of {} must be {} in [{}, {}] {}, got {}", context,
                                            p.name, e.name(), p.integer ? "an integer" : "a number", p.min, p.max,
                                            p.unit, value));
  }
}

}  // namespace

ChainValues::ChainValues() {
  for (const Effect* e : effect_registry()) {
    std::vector<double> v;
    for (const ParamInfo& p : e->params()) v.push_back(p.neutral);
    values_.push_back(std::move(v));
  }
}

double ChainValues::get(std::string_view effect, std::string_view param) const {
  const Effect& e = require_effect(effect, "");
  return values_[registry_index(e)][static_cast<std::size_t>(require_param(e, param, ""))];
}

void ChainValues::set(std::string_view effect, std::string_view param, double value) {
  const Effect& e = require_effect(effect, "");
  const int i = require_param(e, param, "");
  check_range(e, e.params()[static_cast<std::size_t>(i)], value, "");
  values_[registry_index(e)][static_cast<std::size_t>(i)] = value;
}

void ChainValues::apply_spec(std::string_view spec) {
  const std::string context = fmt::format("effect spec '{}': ", spec);
  const std::string_view whole = trim(spec);
  const std::size_t colon = whole.find(':');
  const Effect& e = require_effect(trim(whole.substr(0, colon)), context);
  if (colon == std::string_view::npos || trim(whole.substr(colon + 1)).empty()) {
    const ParamInfo& p = e.params().front();
    throw std::invalid_argument(fmt::format("{}no parameters; write {}:param=value[,param=value] with {} (e.g. {}:{}={})",
                                            context, e.name(), parameter_names(e, false), e.name(), p.name,
                                            p.integer ? p.max : 0.001));
  }
  // Parse into a copy so a bad spec leaves the chain unchanged.
  std::vector<double> updated = values_[registry_index(e)];
  std::string_view rest = whole.substr(colon + 1);
  while (!rest.empty()) {
    const std::size_t comma = rest.find(',');
    const std::string_view item = trim(rest.substr(0, comma));
    rest = comma == std::string_view::npos ? std::string_view{} : rest.substr(comma + 1);
    const std::size_t eq = item.find('=');
    if (eq == std::string_view::npos) {
      throw std::invalid_argument(fmt::format("{}'{}' is not param=value; parameters of {}: {}", context, item,
                                              e.name(), parameter_names(e, false)));
    }
    const int i = require_param(e, trim(item.substr(0, eq)), context);
    const ParamInfo& p = e.params()[static_cast<std::size_t>(i)];
    const std::string_view text = trim(item.substr(eq + 1));
    double value = 0.0;
    const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
    if (ec != std::errc{} || end != text.data() + text.size()) {
      throw std::invalid_argument(
          fmt::format("{}parameter '{}' of {} needs a number {}, got '{}'", context, p.name, e.name(), p.unit, text));
    }
    check_range(e, p, value, context);
    updated[static_cast<std::size_t>(i)] = value;
  }
  try {
    e.validate(updated);
  } catch (const std::invalid_argument& err) {
    throw std::invalid_argument(context + err.what());
  }
  values_[registry_index(e)] = std::move(updated);
}

void ChainValues::validate() const {
  for (const Effect* e : effect_registry()) {
    if (active(*e)) e->validate(of(*e));
  }
}

std::vector<ChainValues::ActiveEffect> ChainValues::active_effects() const {
  std::vector<ActiveEffect> out;
  for (const Effect* e : effect_registry()) {
    if (!active(*e)) continue;
    ActiveEffect a{e, {}};
    const auto ps = e->params();
    const Values v = of(*e);
    for (std::size_t i = 0; i < ps.size(); ++i) {
      // Effects with many parameters (harmonics, mechanical orders) list only the set ones.
      if (ps.size() > 4 && v[i] == ps[i].neutral) continue;
      a.parameters.emplace_back(ps[i].name, v[i]);
    }
    out.push_back(std::move(a));
  }
  return out;
}

}  // namespace resolver
