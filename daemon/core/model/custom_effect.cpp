#include "daemon/core/model/custom_effect.h"

#include <muParser.h>

#include <cmath>
#include <stdexcept>

#include <fmt/format.h>

#include "daemon/core/angles.h"
#include "daemon/core/effects/registry.h"

namespace resolver {

namespace {

CustomSignal parse_signal(const CustomEffectSpec& s) {
  if (s.signal == "position_error") return CustomSignal::kPositionError;
  if (s.signal == "rd_angle") return CustomSignal::kRdAngle;
  if (s.signal == "sin") return CustomSignal::kSin;
  if (s.signal == "cos") return CustomSignal::kCos;
  if (s.signal == "i_d") return CustomSignal::kId;
  if (s.signal == "i_q") return CustomSignal::kIq;
  throw std::invalid_argument(fmt::format("{} custom effect '{}': signal = \"{}\" is not one of position_error, "
                                          "rd_angle, sin, cos, i_d, i_q",
                                          s.origin, s.name, s.signal));
}

std::string_view unit_of(CustomSignal s) {
  switch (s) {
    case CustomSignal::kPositionError:
    case CustomSignal::kRdAngle: return "[rad per unit of the term]";
    case CustomSignal::kSin:
    case CustomSignal::kCos: return "[fraction of amplitude per unit of the term]";
    case CustomSignal::kId:
    case CustomSignal::kIq: return "[A per unit of the term]";
  }
  return "";
}

bool valid_name(std::string_view n) {
  if (n.empty()) return false;
  for (char ch : n) {
    if (!((ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') || (ch >= '0' && ch <= '9') || ch == '_')) return false;
  }
  return true;
}

}  // namespace

CustomEffect::CustomEffect(CustomEffectSpec spec) : spec_(std::move(spec)) {
  if (!valid_name(spec_.name)) {
    throw std::invalid_argument(fmt::format("{}: custom effect name '{}' must be letters, digits and '_' only",
                                            spec_.origin, spec_.name));
  }
  signal_ = parse_signal(spec_);
  if (spec_.terms.empty()) {
    throw std::invalid_argument(fmt::format("{} custom effect '{}': terms = [...] needs at least one expression",
                                            spec_.origin, spec_.name));
  }
  for (std::size_t i = 0; i < spec_.terms.size(); ++i) {
    const std::string& expr = spec_.terms[i];
    auto p = std::make_unique<mu::Parser>();
    try {
      p->DefineVar("theta", &theta_);
      p->DefineVar("theta_m", &theta_m_);
      p->DefineVar("theta_e", &theta_e_);
      p->DefineVar("omega", &omega_);
      p->DefineVar("t", &t_);
      p->SetExpr(expr);
      // Evaluate once now, so an unknown variable or a syntax error is reported here.
      const double v = p->Eval();
      (void)v;
    } catch (const mu::Parser::exception_type& e) {
      throw std::invalid_argument(fmt::format(
          "{} custom effect '{}', term {} \"{}\": {} at column {} (variables: theta, theta_m, theta_e, omega, t; "
          "functions such as sin, cos, sign, abs)",
          spec_.origin, spec_.name, i + 1, expr, e.GetMsg(), e.GetPos() + 1));
    }
    check_finite_somewhere(*p, i);
    const std::string& vars = expr;
    if (vars.find("theta_m") != std::string::npos || vars.find("theta_e") != std::string::npos) needs_reference_ = true;
    parsers_.push_back(std::move(p));
    param_names_.push_back(fmt::format("c{}", i + 1));
  }
  if (signal_ == CustomSignal::kId || signal_ == CustomSignal::kIq) needs_reference_ = true;
  for (std::size_t i = 0; i < spec_.terms.size(); ++i) {
    params_.push_back(ParamInfo{.name = param_names_[i], .unit = unit_of(signal_), .description = spec_.terms[i],
                                .min = -1e12, .max = 1e12});
  }
  description_ = fmt::format("custom: {} += {}", spec_.signal, [&] {
    std::string s;
    for (std::size_t i = 0; i < spec_.terms.size(); ++i) {
      s += fmt::format("{}c{} ({})", i == 0 ? "" : " + ", i + 1, spec_.terms[i]);
    }
    return s;
  }());
  physics_ = spec_.description.empty() ? description_ : spec_.description;
}

CustomEffect::~CustomEffect() = default;

void CustomEffect::check_finite_somewhere(mu::Parser& p, std::size_t i) {
  // A term that is inf or nan wherever it is evaluated (1/(theta-theta)) makes every
  // row unusable, and the fit then reported "not separable". Probed over angles,
  // both directions and a few times; one finite value anywhere lets it through (a
  // pole at one angle, 1/sin(theta), is the data's business, not the config's).
  double bad = 0.0;
  bool finite = false;
  try {
    for (int k = 0; k < 16 && !finite; ++k) {
      for (const double w : {100.0, -100.0, 1.0, -1.0}) {
        for (const double t : {0.0, 1.0, 10.0}) {
          theta_ = kTwoPi * (k + 0.25) / 16.0;
          theta_m_ = theta_ / 3.0;
          theta_e_ = theta_m_ * 4.0;
          omega_ = w;
          t_ = t;
          const double v = p.Eval();
          if (std::isfinite(v)) {
            finite = true;
            break;
          }
          bad = v;
        }
        if (finite) break;
      }
    }
  } catch (const mu::Parser::exception_type&) {
    bad = std::nan("");
  }
  theta_ = theta_m_ = theta_e_ = omega_ = t_ = 0.0;
  if (!finite) {
    throw std::invalid_argument(fmt::format(
        "{} custom effect '{}', term {} \"{}\": evaluates to {} at every angle, speed and time tried (theta "
        "0 .. 2 pi, omega +-1 and +-100 rad/s, t 0 .. 10 s), not a number a coefficient can multiply: a division by "
        "zero, or a function outside its domain; every row would be unusable",
        spec_.origin, spec_.name, i + 1, spec_.terms[i], std::isnan(bad) ? "nan" : (bad > 0 ? "inf" : "-inf")));
  }
}

EffectStage CustomEffect::stage() const {
  switch (signal_) {
    case CustomSignal::kPositionError: return EffectStage::kMotion;
    case CustomSignal::kRdAngle: return EffectStage::kConverter;
    case CustomSignal::kSin:
    case CustomSignal::kCos: return EffectStage::kWindings;
    case CustomSignal::kId:
    case CustomSignal::kIq: return EffectStage::kCurrents;
  }
  return EffectStage::kMotion;
}

bool CustomEffect::compensable() const {
  return signal_ == CustomSignal::kPositionError || signal_ == CustomSignal::kRdAngle;
}

void CustomEffect::bind(const SignatureRow& row) const {
  theta_ = row.theta;
  theta_m_ = row.theta_m;
  theta_e_ = row.theta_e;
  omega_ = row.omega;
  t_ = row.t;
}

double CustomEffect::evaluate(std::size_t i) const {
  try {
    return parsers_.at(i)->Eval();
  } catch (const mu::Parser::exception_type&) {
    return std::nan("");  // checked at construction; a run-time failure makes the row unusable
  }
}

void CustomEffect::signature(const SignatureRow& row, const AngleBasis& b, Values /*v*/, SignatureColumns& out) const {
  const std::lock_guard lock(mutex_);
  bind(row);
  for (std::size_t i = 0; i < parsers_.size(); ++i) {
    const double x = evaluate(i);
    SignalValues& c = out.col(i);
    c = SignalValues{};
    switch (signal_) {
      case CustomSignal::kPositionError: c = SignalValues{.rd = x, .sa = x}; break;
      case CustomSignal::kRdAngle: c.rd = x; break;
      case CustomSignal::kSin: c = envelope_column(b, -b.env_cos(1) * x, x, 0.0); break;
      case CustomSignal::kCos: c = envelope_column(b, b.env_sin(1) * x, 0.0, x); break;
      case CustomSignal::kId: c.d = x; break;
      case CustomSignal::kIq: c.q = x; break;
    }
  }
}

double CustomEffect::term_value(std::size_t i, const SignatureRow& row) const {
  const std::lock_guard lock(mutex_);
  bind(row);
  return evaluate(i);
}

CustomEffects::CustomEffects(const std::vector<CustomEffectSpec>& specs) {
  for (const CustomEffectSpec& s : specs) {
    if (find_effect(s.name) != nullptr) {
      throw std::invalid_argument(fmt::format("{}: custom effect name '{}' is already a catalog effect; choose another",
                                              s.origin, s.name));
    }
    if (find(s.name) != nullptr) {
      throw std::invalid_argument(fmt::format("{}: custom effect name '{}' is used twice", s.origin, s.name));
    }
    effects_.push_back(std::make_unique<CustomEffect>(s));
  }
}

const CustomEffect* CustomEffects::find(std::string_view name) const {
  for (const auto& e : effects_) {
    if (e->name() == name) return e.get();
  }
  return nullptr;
}

}  // namespace resolver
