#include "daemon/core/model/model_spec.h"

#include <algorithm>
#include <cctype>
#include <stdexcept>

#include <fmt/format.h>

#include "daemon/core/effects/registry.h"
#include "daemon/core/model/custom_effect.h"

namespace resolver {

namespace {

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  return s;
}

std::string fittable_names(const CustomEffects* customs) {
  std::string out = effect_names(true);
  if (customs != nullptr) {
    for (const auto& c : customs->all()) out += ", " + std::string(c->name());
  }
  return out;
}

/// " (did you mean 'x'?)" for the fittable effect or custom name closest to `name`, or "".
std::string did_you_mean(std::string_view name, const CustomEffects* customs) {
  std::vector<std::string> names;
  for (const Effect* e : effect_registry()) {
    if (e->fittable()) names.emplace_back(e->name());
  }
  if (customs != nullptr) {
    for (const auto& c : customs->all()) names.emplace_back(c->name());
  }
  const std::string best = closest_name(name, names);
  return best.empty() ? std::string() : " (did you mean '" + best + "'?)";
}

/// Optimal string alignment distance (Levenshtein plus the swap of two neighbours), case ignored.
std::size_t edit_distance(std::string_view a, std::string_view b) {
  const auto lower = [](char ch) { return static_cast<char>(std::tolower(static_cast<unsigned char>(ch))); };
  // d[i][j] = distance between a[0, i) and b[0, j); three rows are enough for the swap.
  std::vector<std::size_t> before(b.size() + 1), previous(b.size() + 1), row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) previous[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t cost = lower(a[i - 1]) == lower(b[j - 1]) ? 0 : 1;
      row[j] = std::min({previous[j] + 1, row[j - 1] + 1, previous[j - 1] + cost});
      if (i > 1 && j > 1 && lower(a[i - 1]) == lower(b[j - 2]) && lower(a[i - 2]) == lower(b[j - 1])) {
        row[j] = std::min(row[j], before[j - 2] + 1);
      }
    }
    std::swap(before, previous);
    std::swap(previous, row);
  }
  return previous[b.size()];
}

ModelTerm parse_one(std::string_view ref, const CustomEffects* customs) {
  const std::size_t open = ref.find('(');
  const std::string_view name = trim(ref.substr(0, open));
  const Effect* e = find_effect(name);
  if (e == nullptr && customs != nullptr) e = customs->find(name);
  if (e == nullptr) {
    throw std::invalid_argument(fmt::format("'{}' is not a fittable catalog effect or a [[model.custom]] name{}; "
                                            "one of: {}",
                                            name, did_you_mean(name, customs), fittable_names(customs)));
  }
  if (!e->fittable()) {
    throw std::invalid_argument(fmt::format("effect '{}' sets the noise floor and is not part of a model; "
                                            "fittable effects: {}",
                                            name, fittable_names(customs)));
  }
  ModelTerm term{e, {}};
  if (open == std::string_view::npos) {
    term.params = default_params(*e);
    return term;
  }
  const std::size_t close = ref.find(')', open);
  if (close == std::string_view::npos || !trim(ref.substr(close + 1)).empty()) {
    throw std::invalid_argument(fmt::format("effect reference '{}': write {}(param,param,...) with a closing ')'",
                                            ref, name));
  }
  std::string_view rest = ref.substr(open + 1, close - open - 1);
  while (!rest.empty()) {
    const std::size_t comma = rest.find(',');
    const std::string_view p = trim(rest.substr(0, comma));
    rest = comma == std::string_view::npos ? std::string_view{} : rest.substr(comma + 1);
    if (p.empty()) continue;
    const int i = find_param(*e, p);
    if (i < 0) {
      std::vector<std::string> params;
      for (const ParamInfo& info : e->params()) params.emplace_back(info.name);
      const std::string best = closest_name(p, params);
      throw std::invalid_argument(fmt::format("effect reference '{}': {} has no parameter '{}'{}; its parameters: {}",
                                              ref, name, p,
                                              best.empty() ? std::string() : " (did you mean '" + best + "'?)",
                                              parameter_names(*e, true)));
    }
    if (std::find(term.params.begin(), term.params.end(), i) == term.params.end()) term.params.push_back(i);
  }
  if (term.params.empty()) {
    throw std::invalid_argument(fmt::format("effect reference '{}': no parameters between the parentheses", ref));
  }
  // A polar pair is fitted as a whole (effect.h: the Cartesian pair).
  const auto ps = e->params();
  for (std::size_t k = 0; k < term.params.size(); ++k) {
    const auto i = static_cast<std::size_t>(term.params[k]);
    if (ps[i].polar == Polar::kAmplitude && i + 1 < ps.size()) term.params.push_back(static_cast<int>(i + 1));
    if (ps[i].polar == Polar::kPhase && i > 0) term.params.push_back(static_cast<int>(i - 1));
  }
  std::sort(term.params.begin(), term.params.end());
  term.params.erase(std::unique(term.params.begin(), term.params.end()), term.params.end());
  return term;
}

}  // namespace

std::vector<int> default_params(const Effect& effect) {
  std::vector<int> out;
  const auto ps = effect.params();
  for (std::size_t i = 0; i < ps.size(); ++i) {
    if (ps[i].default_fit) out.push_back(static_cast<int>(i));
  }
  return out;
}

std::string ModelTerm::reference() const {
  if (params == default_params(*effect)) return std::string(effect->name());
  std::string out = std::string(effect->name()) + "(";
  for (std::size_t i = 0; i < params.size(); ++i) {
    out += (i == 0 ? "" : ",") + std::string(effect->params()[static_cast<std::size_t>(params[i])].name);
  }
  return out + ")";
}

std::string ModelTerm::param_name(std::size_t i) const {
  return std::string(effect->name()) + "." +
         std::string(effect->params()[static_cast<std::size_t>(params[i])].name);
}

std::string closest_name(std::string_view name, std::span<const std::string> candidates) {
  const std::size_t allowed = std::clamp<std::size_t>(name.size() / 3, 1, 3);
  std::string best;
  std::size_t best_distance = allowed + 1;
  for (const std::string& c : candidates) {
    const std::size_t d = edit_distance(name, c);
    if (d < best_distance) {
      best_distance = d;
      best = c;
    }
  }
  return best;
}

std::vector<std::string> split_effect_list(std::string_view text) {
  std::vector<std::string> out;
  int depth = 0;
  std::size_t start = 0;
  for (std::size_t i = 0; i <= text.size(); ++i) {
    const char ch = i < text.size() ? text[i] : ',';
    if (ch == '(') ++depth;
    if (ch == ')') depth = std::max(0, depth - 1);
    if (ch == ',' && depth == 0) {
      const std::string_view item = trim(text.substr(start, i - start));
      if (!item.empty()) out.emplace_back(item);
      start = i + 1;
    }
  }
  return out;
}

ModelSpec ModelSpec::parse(std::span<const std::string> references, const CustomEffects* customs) {
  ModelSpec spec;
  for (const std::string& r : references) {
    for (const std::string& one : split_effect_list(r)) spec.add(parse_one(one, customs));
  }
  return spec;
}

std::vector<std::string> ModelSpec::references() const {
  std::vector<std::string> out;
  for (const ModelTerm& t : terms) out.push_back(t.reference());
  return out;
}

const ModelTerm* ModelSpec::find(const Effect& effect) const {
  for (const ModelTerm& t : terms) {
    if (t.effect == &effect) return &t;
  }
  return nullptr;
}

void ModelSpec::add(const ModelTerm& term) {
  for (ModelTerm& t : terms) {
    if (t.effect != term.effect) continue;
    for (int p : term.params) {
      if (std::find(t.params.begin(), t.params.end(), p) == t.params.end()) t.params.push_back(p);
    }
    std::sort(t.params.begin(), t.params.end());
    return;
  }
  terms.push_back(term);
}

ModelSpec ModelSpec::for_parameters(std::span<const std::string> names) {
  ModelSpec spec;
  for (const std::string& name : names) {
    const std::size_t dot = name.find('.');
    if (dot == std::string::npos) continue;
    const Effect* e = find_effect(std::string_view(name).substr(0, dot));
    if (e == nullptr) continue;
    const int i = find_param(*e, std::string_view(name).substr(dot + 1));
    if (i >= 0) spec.add(ModelTerm{e, {i}});
  }
  return spec;
}

std::size_t ModelSpec::parameter_count() const {
  std::size_t n = 0;
  for (const ModelTerm& t : terms) n += t.params.size();
  return n;
}

}  // namespace resolver
