// The effect registry (registry.h) and the chain values it spells (chain_values.h):
// the names scripts and configs rely on, every parameter's self-description, the
// spec parser and its messages, ranges and integer parameters, the truth files'
// list of active effects, and the catalog listing through the real resolver-sim.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <set>
#include <stdexcept>
#include <string>
#include <sys/wait.h>
#include <vector>

#include "daemon/core/effects/chain_values.h"
#include "daemon/core/effects/registry.h"

namespace resolver {
namespace {

/// "effect:param=value" with the value printed to round-trip.
std::string fmt_spec(std::string_view effect, std::string_view param, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return std::string(effect) + ":" + std::string(param) + "=" + buf;
}

/// The effect names, and the parameter names, that the project's interface uses
/// (CLI --effect, TOML [sim] effects and [model] effects, truth files, reports,
/// tools/demo.sh, docs): renaming one breaks users, so it must fail here. Effects
/// in registry order (the catalog's); per effect its full parameter list, or for
/// the long ones (harmonics, mechanical_harmonics) the first few names (the rest
/// are checked by pattern below).
const std::vector<std::pair<std::string, std::vector<std::string>>>& stable_names() {
  static const std::vector<std::pair<std::string, std::vector<std::string>>> names{
      {"amplitude_imbalance", {"alpha"}},
      {"quadrature", {"beta"}},
      {"offsets", {"o_s", "o_c"}},
      {"harmonics", {"k0", "k2", "k3", "k4", "k5"}},
      {"envelope_drift", {"g"}},
      {"sampling_skew", {"tau"}},
      {"channel_delay", {"tau"}},
      {"tracking_loop", {"omega_n", "zeta"}},
      {"quantization", {"rd_bits"}},
      {"backlash", {"h"}},
      {"eccentricity", {"e", "phase"}},
      {"mechanical_harmonics", {"a1", "b1", "a2", "b2"}},
      {"mounting_offset", {"theta_0"}},
      {"delay", {"d"}},
      {"current_offsets", {"off_a", "off_b"}},
      {"current_gain_mismatch", {"gain_a", "gain_b"}},
      {"dead_time", {"t_d"}},
      {"noise", {"sigma_sc", "sigma_i"}},
      {"outliers", {"rate", "size"}},
      {"current_outliers", {"rate", "size", "positive"}},
  };
  return names;
}

TEST(EffectRegistry, NamesAreStable) {
  const auto& expected = stable_names();
  const auto registry = effect_registry();
  ASSERT_EQ(registry.size(), expected.size()) << "a new effect: add it to stable_names() (its names become interface)";
  for (std::size_t i = 0; i < expected.size(); ++i) {
    const Effect& e = *registry[i];
    EXPECT_EQ(e.name(), expected[i].first) << "registry position " << i;
    const auto params = e.params();
    const std::vector<std::string>& want = expected[i].second;
    ASSERT_GE(params.size(), want.size()) << e.name();
    for (std::size_t k = 0; k < want.size(); ++k) EXPECT_EQ(params[k].name, want[k]) << e.name() << " parameter " << k;
    if (e.name() != "harmonics" && e.name() != "mechanical_harmonics") {
      EXPECT_EQ(params.size(), want.size()) << e.name() << ": a parameter was added; list it here";
    }
  }
  // The long ones: harmonics k0, k2..k20, k2_opp..k20_opp and their quadrature parts
  // (each order's own phase); mechanical orders a1/b1..a16/b16.
  const Effect& h = *find_effect("harmonics");
  EXPECT_EQ(h.params().size(), 1U + 4U * 19U);
  for (int n = 2; n <= 20; ++n) {
    EXPECT_GE(find_param(h, "k" + std::to_string(n)), 0) << n;
    EXPECT_GE(find_param(h, "k" + std::to_string(n) + "_opp"), 0) << n;
    EXPECT_GE(find_param(h, "k" + std::to_string(n) + "_q"), 0) << n;
    EXPECT_GE(find_param(h, "k" + std::to_string(n) + "_opp_q"), 0) << n;
  }
  EXPECT_LT(find_param(h, "k1"), 0) << "K_1 is the fundamental itself";
  EXPECT_LT(find_param(h, "k21"), 0);
  const Effect& m = *find_effect("mechanical_harmonics");
  EXPECT_EQ(m.params().size(), 32U);
  for (int n = 1; n <= 16; ++n) {
    EXPECT_GE(find_param(m, "a" + std::to_string(n)), 0) << n;
    EXPECT_GE(find_param(m, "b" + std::to_string(n)), 0) << n;
  }
}

TEST(EffectRegistry, LookupsAgreeWithTheList) {
  const auto registry = effect_registry();
  for (std::size_t i = 0; i < registry.size(); ++i) {
    const Effect& e = *registry[i];
    EXPECT_EQ(find_effect(e.name()), &e);
    EXPECT_EQ(registry_index(e), i);
    for (std::size_t k = 0; k < e.params().size(); ++k) {
      EXPECT_EQ(find_param(e, e.params()[k].name), static_cast<int>(k)) << e.name();
    }
  }
  EXPECT_EQ(find_effect("amplitude_imbalanse"), nullptr);
  EXPECT_EQ(find_effect(""), nullptr);
  EXPECT_EQ(find_param(*find_effect("offsets"), "o_x"), -1);
  // Fittable names exclude the floor-setting impairments only.
  const std::string fittable = effect_names(true);
  EXPECT_EQ(fittable.find("noise"), std::string::npos);
  EXPECT_EQ(fittable.find("outliers"), std::string::npos);
  EXPECT_EQ(fittable.find("quantization"), std::string::npos);
  EXPECT_NE(fittable.find("delay"), std::string::npos);
  EXPECT_NE(effect_names(false).find("outliers"), std::string::npos);
}

TEST(EffectRegistry, EveryEffectAndParameterDescribesItself) {
  for (const Effect* e : effect_registry()) {
    EXPECT_FALSE(e->description().empty()) << e->name();
    EXPECT_FALSE(e->source().empty()) << e->name();
    EXPECT_FALSE(e->physics().empty()) << e->name();
    ASSERT_FALSE(e->params().empty()) << e->name();
    std::set<std::string_view> names;
    std::vector<double> neutral;
    for (const ParamInfo& p : e->params()) {
      EXPECT_TRUE(names.insert(p.name).second) << e->name() << " repeats " << p.name;
      // A unit in brackets, e.g. "[rad]", "[1]", "[fraction of amplitude]".
      ASSERT_GE(p.unit.size(), 3U) << e->name() << "." << p.name;
      EXPECT_EQ(p.unit.front(), '[') << e->name() << "." << p.name;
      EXPECT_EQ(p.unit.back(), ']') << e->name() << "." << p.name;
      EXPECT_GE(p.description.size(), 10U) << e->name() << "." << p.name << ": one line of description";
      EXPECT_LT(p.min, p.max) << e->name() << "." << p.name;
      EXPECT_TRUE(std::isfinite(p.min) && std::isfinite(p.max)) << e->name() << "." << p.name;
      EXPECT_GE(p.neutral, p.min) << e->name() << "." << p.name;
      EXPECT_LE(p.neutral, p.max) << e->name() << "." << p.name;
      if (p.integer) {
        EXPECT_EQ(p.min, std::round(p.min)) << p.name;
        EXPECT_EQ(p.max, std::round(p.max)) << p.name;
        EXPECT_EQ(p.neutral, std::round(p.neutral)) << p.name;
      }
      if (p.scale != FitScale::kLinear) {
        EXPECT_TRUE(p.nonlinear) << p.name << ": a fit scale for a linear parameter";
      }
      neutral.push_back(p.neutral);
    }
    // At its neutral values an effect does nothing: the default chain is ideal.
    EXPECT_FALSE(e->active(neutral)) << e->name();
    EXPECT_NO_THROW(e->validate(neutral)) << e->name();
  }
}

TEST(ChainValues, DefaultChainIsIdealAndHasNoActiveEffect) {
  const ChainValues v;
  EXPECT_TRUE(v.active_effects().empty());
  for (const Effect* e : effect_registry()) {
    EXPECT_FALSE(v.active(*e)) << e->name();
    for (std::size_t k = 0; k < e->params().size(); ++k) {
      EXPECT_EQ(v.of(*e)[k], e->params()[k].neutral) << e->name();
      EXPECT_EQ(v.get(e->name(), e->params()[k].name), e->params()[k].neutral);
    }
  }
  EXPECT_NO_THROW(v.validate());
}

TEST(ChainValues, SpecsSetTheParameters) {
  ChainValues c;
  c.apply_spec("amplitude_imbalance:alpha=0.003");
  c.apply_spec("quadrature:beta=0.004");
  c.apply_spec("offsets:o_s=0.001,o_c=-0.002");
  c.apply_spec(" tracking_loop : omega_n = 3000 , zeta=0.7 ");
  c.apply_spec("noise:sigma_sc=2");
  c.apply_spec("quantization:rd_bits=12");
  c.apply_spec("harmonics:k0=0.001,k3=-2e-4,k16=1e-5,k3_opp=3e-4");
  c.apply_spec("envelope_drift:g=-2e-4");
  EXPECT_DOUBLE_EQ(c.get("amplitude_imbalance", "alpha"), 0.003);
  EXPECT_DOUBLE_EQ(c.get("quadrature", "beta"), 0.004);
  EXPECT_DOUBLE_EQ(c.get("offsets", "o_s"), 0.001);
  EXPECT_DOUBLE_EQ(c.get("offsets", "o_c"), -0.002);
  EXPECT_DOUBLE_EQ(c.get("tracking_loop", "omega_n"), 3000.0);
  EXPECT_DOUBLE_EQ(c.get("tracking_loop", "zeta"), 0.7);
  EXPECT_DOUBLE_EQ(c.get("noise", "sigma_sc"), 2.0);
  EXPECT_EQ(c.get("quantization", "rd_bits"), 12.0);
  EXPECT_DOUBLE_EQ(c.get("harmonics", "k0"), 0.001);
  EXPECT_DOUBLE_EQ(c.get("harmonics", "k3"), -2e-4);
  EXPECT_DOUBLE_EQ(c.get("harmonics", "k16"), 1e-5);
  EXPECT_DOUBLE_EQ(c.get("harmonics", "k3_opp"), 3e-4);
  EXPECT_DOUBLE_EQ(c.get("envelope_drift", "g"), -2e-4);
  c.apply_spec("sampling_skew:tau=2e-6");
  c.apply_spec("channel_delay:tau=-3e-6");
  c.apply_spec("backlash:h=0.01");
  c.apply_spec("eccentricity:e=5e-4,phase=1.2");
  c.apply_spec("mechanical_harmonics:a2=1e-4,b2=-2e-4");
  c.apply_spec("mounting_offset:theta_0=-0.05");
  c.apply_spec("delay:d=2e-3");
  c.apply_spec("current_offsets:off_a=0.05,off_b=-0.03");
  c.apply_spec("current_gain_mismatch:gain_a=0.01,gain_b=-0.005");
  c.apply_spec("dead_time:t_d=2e-6");
  c.apply_spec("outliers:rate=5,size=3000");
  c.apply_spec("current_outliers:rate=20,size=8,positive=1");
  EXPECT_DOUBLE_EQ(c.get("sampling_skew", "tau"), 2e-6);
  EXPECT_DOUBLE_EQ(c.get("channel_delay", "tau"), -3e-6);
  EXPECT_DOUBLE_EQ(c.get("backlash", "h"), 0.01);
  EXPECT_DOUBLE_EQ(c.get("eccentricity", "e"), 5e-4);
  EXPECT_DOUBLE_EQ(c.get("eccentricity", "phase"), 1.2);
  EXPECT_DOUBLE_EQ(c.get("mechanical_harmonics", "a2"), 1e-4);
  EXPECT_DOUBLE_EQ(c.get("mechanical_harmonics", "b2"), -2e-4);
  EXPECT_DOUBLE_EQ(c.get("mounting_offset", "theta_0"), -0.05);
  EXPECT_DOUBLE_EQ(c.get("delay", "d"), 2e-3);
  EXPECT_DOUBLE_EQ(c.get("current_offsets", "off_a"), 0.05);
  EXPECT_DOUBLE_EQ(c.get("current_offsets", "off_b"), -0.03);
  EXPECT_DOUBLE_EQ(c.get("current_gain_mismatch", "gain_a"), 0.01);
  EXPECT_DOUBLE_EQ(c.get("current_gain_mismatch", "gain_b"), -0.005);
  EXPECT_DOUBLE_EQ(c.get("dead_time", "t_d"), 2e-6);
  EXPECT_DOUBLE_EQ(c.get("outliers", "rate"), 5.0);
  EXPECT_DOUBLE_EQ(c.get("outliers", "size"), 3000.0);
  EXPECT_DOUBLE_EQ(c.get("current_outliers", "rate"), 20.0);
  EXPECT_DOUBLE_EQ(c.get("current_outliers", "size"), 8.0);
  EXPECT_DOUBLE_EQ(c.get("current_outliers", "positive"), 1.0);
  // A later spec of the same parameter wins, the others stay.
  c.apply_spec("offsets:o_c=0.004");
  EXPECT_DOUBLE_EQ(c.get("offsets", "o_s"), 0.001);
  EXPECT_DOUBLE_EQ(c.get("offsets", "o_c"), 0.004);

  // Every effect is active now, in registry order; what truth files record.
  const std::vector<ChainValues::ActiveEffect> active = c.active_effects();
  std::vector<std::string_view> names;
  names.reserve(active.size());
  for (const auto& a : active) names.push_back(a.effect->name());
  std::vector<std::string_view> all;
  all.reserve(effect_registry().size());
  for (const Effect* e : effect_registry()) all.push_back(e->name());
  EXPECT_EQ(names, all);
  const auto of = [&](std::string_view name) -> const ChainValues::ActiveEffect& {
    for (const auto& a : active) {
      if (a.effect->name() == name) return a;
    }
    throw std::logic_error("not active");
  };
  // Long effects list only their set parameters; short ones all of them (zeros included).
  using Params = std::vector<std::pair<std::string_view, double>>;
  EXPECT_EQ(of("harmonics").parameters, (Params{{"k0", 0.001}, {"k3", -2e-4}, {"k16", 1e-5}, {"k3_opp", 3e-4}}));
  EXPECT_EQ(of("mechanical_harmonics").parameters, (Params{{"a2", 1e-4}, {"b2", -2e-4}}));
  EXPECT_EQ(of("eccentricity").parameters, (Params{{"e", 5e-4}, {"phase", 1.2}}));
  EXPECT_EQ(of("tracking_loop").parameters, (Params{{"omega_n", 3000.0}, {"zeta", 0.7}}));
  ChainValues gain_a_only;
  gain_a_only.apply_spec("current_gain_mismatch:gain_a=0.01");
  ASSERT_EQ(gain_a_only.active_effects().size(), 1U);
  EXPECT_EQ(gain_a_only.active_effects()[0].parameters, (Params{{"gain_a", 0.01}, {"gain_b", 0.0}}));
}

/// A value of `p` inside its range, away from its neutral value and small enough
/// for every effect's whole-set check (mechanical_harmonics: sum n |a_n| < 1).
double test_value(const ParamInfo& p) {
  if (p.integer) return p.neutral != p.min ? p.min : p.max;
  return p.neutral < p.max ? p.neutral + 0.01 * (p.max - p.neutral) : p.neutral - 0.01 * (p.neutral - p.min);
}

TEST(ChainValues, EveryParameterRoundTripsThroughSpecSetAndGet) {
  for (const Effect* e : effect_registry()) {
    for (const ParamInfo& p : e->params()) {
      const double v = test_value(p);
      ASSERT_NE(v, p.neutral) << e->name() << "." << p.name;
      ChainValues by_spec;
      ASSERT_NO_THROW(by_spec.apply_spec(fmt_spec(e->name(), p.name, v))) << e->name() << "." << p.name;
      EXPECT_EQ(by_spec.get(e->name(), p.name), v) << e->name() << ":" << p.name;
      ChainValues by_set;
      by_set.set(e->name(), p.name, v);
      EXPECT_EQ(by_set.get(e->name(), p.name), v) << e->name() << ":" << p.name;
      EXPECT_EQ(by_set.of(*e)[static_cast<std::size_t>(find_param(*e, p.name))], v);
      // Only this effect changed.
      for (const Effect* other : effect_registry()) {
        if (other != e) {
          EXPECT_FALSE(by_set.active(*other)) << e->name() << "." << p.name << " moved " << other->name();
        }
      }
    }
  }
}

/// The message of the std::invalid_argument `f` throws ("" and a test failure if none).
template <typename F>
std::string error_of(F&& f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  ADD_FAILURE() << "no std::invalid_argument";
  return {};
}

TEST(ChainValues, RangesAreInclusiveAndCheckedAtBothEnds) {
  for (const Effect* e : effect_registry()) {
    for (const ParamInfo& p : e->params()) {
      ChainValues c;
      EXPECT_NO_THROW(c.set(e->name(), p.name, p.min)) << e->name() << "." << p.name;
      EXPECT_NO_THROW(c.set(e->name(), p.name, p.max)) << e->name() << "." << p.name;
      for (const double bad : {std::nextafter(p.max, 2.0 * std::abs(p.max) + 1.0),
                               std::nextafter(p.min, -2.0 * std::abs(p.min) - 1.0),
                               std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
        const std::string msg = error_of([&] { c.set(e->name(), p.name, bad); });
        // The message names the parameter, the effect, the unit and the range.
        EXPECT_NE(msg.find(std::string(p.name)), std::string::npos) << msg;
        EXPECT_NE(msg.find(std::string(e->name())), std::string::npos) << msg;
        EXPECT_NE(msg.find(std::string(p.unit)), std::string::npos) << msg;
        EXPECT_EQ(c.get(e->name(), p.name), p.max) << "a refused value must not change the chain";
      }
    }
  }
}

TEST(ChainValues, IntegerParametersRefuseFractions) {
  int integers = 0;
  for (const Effect* e : effect_registry()) {
    for (const ParamInfo& p : e->params()) {
      if (!p.integer) continue;
      ++integers;
      ChainValues c;
      const double whole = std::floor(0.5 * (p.min + p.max));  // inside the range
      const double fraction = whole + 0.5;
      EXPECT_NE(error_of([&] { c.set(e->name(), p.name, fraction); }).find("integer"), std::string::npos);
      EXPECT_NE(error_of([&] { c.apply_spec(fmt_spec(e->name(), p.name, fraction)); }).find("integer"),
                std::string::npos);
      EXPECT_EQ(c.get(e->name(), p.name), p.neutral);
      EXPECT_NO_THROW(c.apply_spec(fmt_spec(e->name(), p.name, whole)));
    }
  }
  EXPECT_GE(integers, 1) << "quantization.rd_bits is an integer parameter";
}

/// Applies a bad spec and checks the message names what is wrong; the chain is unchanged.
void expect_error(std::string_view spec, std::initializer_list<std::string_view> must_mention) {
  ChainValues c;
  c.set("amplitude_imbalance", "alpha", 0.5e-3);
  const std::string msg = error_of([&] { c.apply_spec(spec); });
  for (std::string_view word : must_mention) EXPECT_NE(msg.find(word), std::string::npos) << spec << ": " << msg;
  EXPECT_NE(msg.find(spec), std::string::npos) << "the message quotes the spec: " << msg;
  EXPECT_DOUBLE_EQ(c.get("amplitude_imbalance", "alpha"), 0.5e-3) << "a failed spec must not change the chain";
  EXPECT_DOUBLE_EQ(c.get("offsets", "o_s"), 0.0) << "a failed spec must not change the chain";
  EXPECT_DOUBLE_EQ(c.get("mechanical_harmonics", "a1"), 0.0) << "a failed spec must not change the chain";
}

TEST(ChainValues, BadSpecsSayWhatIsWrong) {
  // Unknown effect: lists the valid ones.
  expect_error("amplitude_imbalanse:alpha=0.1", {"unknown effect", "amplitude_imbalanse", "amplitude_imbalance",
                                                 "quadrature", "mechanical_harmonics", "--list-effects"});
  // Unknown parameter: lists the effect's parameters.
  expect_error("amplitude_imbalance:alfa=0.1", {"alfa", "alpha"});
  expect_error("eccentricity:ee=0.001", {"ee", "e, phase"});
  expect_error("current_offsets:off_c=0.1", {"off_c", "off_a, off_b"});
  expect_error("harmonics:k1=0.1", {"k1", "k0", "k20_opp"});
  expect_error("delay:tau=0.001", {"tau", "valid parameters: d"});
  // Bad values.
  expect_error("amplitude_imbalance:alpha=abc", {"alpha", "abc", "number"});
  expect_error("amplitude_imbalance:alpha=0.1x", {"alpha", "0.1x"});
  expect_error("amplitude_imbalance:alpha=", {"alpha"});
  expect_error("amplitude_imbalance:alpha=2", {"alpha", "0.5", "got 2"});
  expect_error("offsets:o_s=0.01,o_c=oops", {"o_c", "oops"});  // the good o_s is not applied either
  expect_error("quantization:rd_bits=12.5", {"rd_bits", "integer"});
  expect_error("quantization:rd_bits=17", {"rd_bits", "16"});
  expect_error("sampling_skew:tau=0.01", {"tau", "[s]"});
  expect_error("channel_delay:tau=-0.01", {"tau", "channel_delay", "[s]"});
  expect_error("eccentricity:e=0.6", {"eccentricity", "'e'"});
  expect_error("mounting_offset:theta_0=4", {"theta_0", "[rad]"});
  expect_error("current_gain_mismatch:gain_a=-0.7", {"gain_a"});
  expect_error("dead_time:t_d=-1e-6", {"t_d", "[s]"});
  expect_error("backlash:h=-0.01", {"'h'", "backlash", "[rad]"});
  expect_error("envelope_drift:g=0.1", {"'g'", "envelope_drift", "[1/s]"});
  expect_error("outliers:rate=-1", {"rate", "[1/s]"});
  // Grammar.
  expect_error("amplitude_imbalance", {"no parameters", "alpha"});
  expect_error("amplitude_imbalance:", {"no parameters", "alpha"});
  expect_error("amplitude_imbalance:alpha", {"param=value"});
  // A whole-set check beyond the ranges: sum n (|a_n| + |b_n|) < 1 keeps the seen angle monotone.
  expect_error("mechanical_harmonics:a1=0.4,a2=0.4", {"mechanical_harmonics", "< 1"});
}

TEST(ChainValues, SetAndGetNameTheUnknownEffectOrParameter) {
  ChainValues c;
  EXPECT_NE(error_of([&] { c.set("no_such_effect", "x", 1.0); }).find("no_such_effect"), std::string::npos);
  EXPECT_NE(error_of([&] { (void)c.get("no_such_effect", "x"); }).find("no_such_effect"), std::string::npos);
  const std::string msg = error_of([&] { c.set("quadrature", "alpha", 0.01); });
  EXPECT_NE(msg.find("'alpha'"), std::string::npos) << msg;
  EXPECT_NE(msg.find("beta"), std::string::npos) << msg;
  EXPECT_NE(error_of([&] { (void)c.get("quadrature", "gamma"); }).find("gamma"), std::string::npos);
  // set() checks ranges only; the whole set is checked by validate(), which the forward chain calls.
  c.set("mechanical_harmonics", "a1", 0.4);
  c.set("mechanical_harmonics", "a2", 0.4);
  EXPECT_NE(error_of([&] { c.validate(); }).find("mechanical_harmonics"), std::string::npos);
}

TEST(EffectRegistry, CatalogListingShowsEveryEffectAndListedParameter) {
  const std::string text = format_effect_catalog();
  for (const Effect* e : effect_registry()) {
    EXPECT_NE(text.find("  " + std::string(e->name()) + " "), std::string::npos) << e->name();
    std::size_t hidden = 0;
    for (const ParamInfo& p : e->params()) {
      if (!p.listed) {
        ++hidden;
        continue;
      }
      EXPECT_NE(text.find("      " + std::string(p.name) + " "), std::string::npos) << e->name() << "." << p.name;
    }
    if (hidden > 0) {
      EXPECT_NE(text.find("and " + std::to_string(hidden) + " more"), std::string::npos) << e->name();
    }
  }
  EXPECT_NE(text.find("[rad/s]"), std::string::npos);
  EXPECT_NE(text.find("(nonlinear)"), std::string::npos);
  EXPECT_NE(text.find("not fitted"), std::string::npos);
  EXPECT_EQ(text.find("not implemented"), std::string::npos);
}

TEST(EffectRegistry, MarkdownHasASectionAndEveryParameterPerEffect) {
  const std::string md = effects_markdown();
  EXPECT_EQ(md.rfind("# Effect catalog\n", 0), 0U);
  for (const Effect* e : effect_registry()) {
    EXPECT_NE(md.find("\n## `" + std::string(e->name()) + "`\n"), std::string::npos) << e->name();
    for (const ParamInfo& p : e->params()) {
      // Every parameter, listed or not, has its row: the docs are the complete reference.
      EXPECT_NE(md.find("| `" + std::string(p.name) + "` | " + std::string(p.unit) + " |"), std::string::npos)
          << e->name() << "." << p.name;
    }
  }
}

struct SimRun {
  int status = -1;
  std::string out;  ///< stdout only
};

SimRun run_sim(const std::string& args) {
  SimRun r;
  FILE* pipe = ::popen((std::string(RESOLVER_SIM_EXE) + " " + args + " 2>/dev/null").c_str(), "r");
  if (pipe == nullptr) return r;
  char buf[4096];
  std::size_t n = 0;
  while ((n = std::fread(buf, 1, sizeof buf, pipe)) > 0) r.out.append(buf, n);
  const int raw = ::pclose(pipe);
  r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  return r;
}

// Through the real program: what a user reads is what the registry says.
TEST(EffectRegistry, ResolverSimListsTheRegistry) {
  const SimRun list = run_sim("--list-effects");
  EXPECT_EQ(list.status, 0);
  EXPECT_EQ(list.out, format_effect_catalog());
  for (const auto& [effect, params] : stable_names()) {
    EXPECT_NE(list.out.find("  " + effect + " "), std::string::npos) << effect;
    EXPECT_NE(list.out.find("      " + params.front() + " "), std::string::npos) << effect << "." << params.front();
  }
  const SimRun md = run_sim("--effects-markdown");
  EXPECT_EQ(md.status, 0);
  EXPECT_EQ(md.out, effects_markdown());
}

// Issue 22: a parameter's range is listed once, in its ParamInfo. An effect's own
// validate() checks only what one parameter's range cannot say (a whole set, a pair),
// so every single value in the listed range, the others neutral, is valid.
TEST(EffectRegistry, ValidateAcceptsEveryListedRangeEnd) {
  for (const Effect* e : effect_registry()) {
    std::vector<double> v;
    for (const ParamInfo& p : e->params()) v.push_back(p.neutral);
    for (std::size_t i = 0; i < v.size(); ++i) {
      const ParamInfo& p = e->params()[i];
      for (const double x : {p.min, p.max}) {
        std::vector<double> w = v;
        w[i] = x;
        EXPECT_NO_THROW(e->validate(w)) << e->name() << "." << p.name << " = " << x
                                        << " is in its listed range but refused";
      }
    }
  }
}

}  // namespace
}  // namespace resolver
