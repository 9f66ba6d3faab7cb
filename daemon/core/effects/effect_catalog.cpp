#include "daemon/core/effects/effect_catalog.h"

#include <array>
#include <charconv>
#include <cmath>
#include <system_error>

#include "daemon/core/angles.h"

#include <fmt/format.h>

namespace resolver {

namespace {

// Ranges: wide enough for any real resolver, narrow enough that the model's
// small-parameter picture (and the estimators built on it) still holds.
constexpr double kSmall = 0.5;  // [1] or [rad]: beyond this an "imperfection" is a fault

template <std::size_t N>
void set_k(SensorChainConfig& c, double v) {
  c.harmonics.k[N] = v;
}
template <std::size_t N>
double get_k(const SensorChainConfig& c) {
  return c.harmonics.k[N];
}
template <std::size_t N>
constexpr EffectParameter harmonic_param(std::string_view name, bool listed) {
  return {name, "[fraction of fundamental]", "inductance harmonic K_n of order n (Hanselman eq. 8)",
          -kSmall, kSmall, false, listed, &set_k<N>, &get_k<N>};
}

constexpr std::array kAmplitudeImbalance{
    EffectParameter{"alpha", "[1]", "relative gain error of the cos channel", -kSmall, kSmall, false, true,
                    [](SensorChainConfig& c, double v) { c.amplitude_imbalance.alpha = v; },
                    [](const SensorChainConfig& c) { return c.amplitude_imbalance.alpha; }},
};
constexpr std::array kQuadrature{
    EffectParameter{"beta", "[rad]", "misalignment of the cos winding", -kSmall, kSmall, false, true,
                    [](SensorChainConfig& c, double v) { c.quadrature.beta = v; },
                    [](const SensorChainConfig& c) { return c.quadrature.beta; }},
};
constexpr std::array kOffsets{
    EffectParameter{"o_s", "[fraction of amplitude]", "DC offset of the sin channel", -kSmall, kSmall, false, true,
                    [](SensorChainConfig& c, double v) { c.offsets.o_s = v; },
                    [](const SensorChainConfig& c) { return c.offsets.o_s; }},
    EffectParameter{"o_c", "[fraction of amplitude]", "DC offset of the cos channel", -kSmall, kSmall, false, true,
                    [](SensorChainConfig& c, double v) { c.offsets.o_c = v; },
                    [](const SensorChainConfig& c) { return c.offsets.o_c; }},
};
constexpr std::array kHarmonics{
    EffectParameter{"k0", "[fraction of fundamental]", "inductive DC component K_0 on both channels", -kSmall,
                    kSmall, false, true, [](SensorChainConfig& c, double v) { c.harmonics.k0 = v; },
                    [](const SensorChainConfig& c) { return c.harmonics.k0; }},
    harmonic_param<2>("k2", true),    harmonic_param<3>("k3", true),    harmonic_param<4>("k4", true),
    harmonic_param<5>("k5", true),    harmonic_param<6>("k6", false),   harmonic_param<7>("k7", false),
    harmonic_param<8>("k8", false),   harmonic_param<9>("k9", false),   harmonic_param<10>("k10", false),
    harmonic_param<11>("k11", false), harmonic_param<12>("k12", false), harmonic_param<13>("k13", false),
    harmonic_param<14>("k14", false), harmonic_param<15>("k15", false), harmonic_param<16>("k16", false),
};
static_assert(kHarmonics.size() == Harmonics::kMaxOrder, "one row for k0 and each of k2..kMaxOrder");
constexpr std::array kSamplingSkew{
    EffectParameter{"tau", "[s]", "delay of the cos sample after the sin sample", -1e-3, 1e-3, false, true,
                    [](SensorChainConfig& c, double v) { c.sampling_skew.tau = v; },
                    [](const SensorChainConfig& c) { return c.sampling_skew.tau; }},
};
constexpr std::array kTrackingLoop{
    EffectParameter{"omega_n", "[rad/s]", "closed-loop natural frequency (0 = ideal converter)", 0.0, 1e6, false,
                    true, [](SensorChainConfig& c, double v) { c.tracking_loop.omega_n = v; },
                    [](const SensorChainConfig& c) { return c.tracking_loop.omega_n; }},
    EffectParameter{"zeta", "[1]", "closed-loop damping ratio", 0.01, 10.0, false, true,
                    [](SensorChainConfig& c, double v) { c.tracking_loop.zeta = v; },
                    [](const SensorChainConfig& c) { return c.tracking_loop.zeta; }},
};
constexpr std::array kQuantization{
    EffectParameter{"rd_bits", "[bits]", "R/D converter resolution", Quantization::kMinBits, Quantization::kMaxBits,
                    true, true,
                    [](SensorChainConfig& c, double v) { c.quantization.rd_bits = static_cast<int>(v); },
                    [](const SensorChainConfig& c) { return static_cast<double>(c.quantization.rd_bits); }},
};
constexpr std::array kEccentricity{
    EffectParameter{"e", "[rad]", "amplitude of the 1x angle error (mechanical rad)", -kSmall, kSmall, false, true,
                    [](SensorChainConfig& c, double v) { c.eccentricity.e = v; },
                    [](const SensorChainConfig& c) { return c.eccentricity.e; }},
    EffectParameter{"phase", "[rad]", "phase of the 1x angle error (mechanical rad)", -10.0, 10.0, false, true,
                    [](SensorChainConfig& c, double v) { c.eccentricity.phase = v; },
                    [](const SensorChainConfig& c) { return c.eccentricity.phase; }},
};
constexpr std::array kMountingOffset{
    EffectParameter{"theta_0", "[rad]", "drive (resolver) zero ahead of the rotor d axis (motor electrical rad)",
                    -kPi, kPi, false, true, [](SensorChainConfig& c, double v) { c.mounting_offset.theta_0 = v; },
                    [](const SensorChainConfig& c) { return c.mounting_offset.theta_0; }},
};
constexpr std::array kCurrentOffsets{
    EffectParameter{"off_a", "[A]", "offset of the phase a current sensor", -1000.0, 1000.0, false, true,
                    [](SensorChainConfig& c, double v) { c.current_offsets.off_a = v; },
                    [](const SensorChainConfig& c) { return c.current_offsets.off_a; }},
    EffectParameter{"off_b", "[A]", "offset of the phase b current sensor", -1000.0, 1000.0, false, true,
                    [](SensorChainConfig& c, double v) { c.current_offsets.off_b = v; },
                    [](const SensorChainConfig& c) { return c.current_offsets.off_b; }},
};
constexpr std::array kCurrentGain{
    EffectParameter{"gain_a", "[1]", "relative gain error of the phase a current sensor", -kSmall, kSmall, false,
                    true, [](SensorChainConfig& c, double v) { c.current_gain_mismatch.gain_a = v; },
                    [](const SensorChainConfig& c) { return c.current_gain_mismatch.gain_a; }},
    EffectParameter{"gain_b", "[1]", "relative gain error of the phase b current sensor", -kSmall, kSmall, false,
                    true, [](SensorChainConfig& c, double v) { c.current_gain_mismatch.gain_b = v; },
                    [](const SensorChainConfig& c) { return c.current_gain_mismatch.gain_b; }},
};
constexpr std::array kDeadTime{
    // 20 us is already an extreme dead time; it gives k_dt = 0.2 (dead_time.h).
    EffectParameter{"t_d", "[s]", "inverter dead time (5th/7th current harmonics k_dt = t_d / 100 us)", 0.0, 2e-5,
                    false, true, [](SensorChainConfig& c, double v) { c.dead_time.t_d = v; },
                    [](const SensorChainConfig& c) { return c.dead_time.t_d; }},
};
constexpr std::array kNoise{
    EffectParameter{"sigma_sc", "[counts]", "white noise on each sin/cos ADC sample", 0.0, 32767.0, false, true,
                    [](SensorChainConfig& c, double v) { c.noise.sigma_sc = v; },
                    [](const SensorChainConfig& c) { return c.noise.sigma_sc; }},
    EffectParameter{"sigma_i", "[A]", "white noise on each phase current sample", 0.0, 1000.0, false, true,
                    [](SensorChainConfig& c, double v) { c.noise.sigma_i = v; },
                    [](const SensorChainConfig& c) { return c.noise.sigma_i; }},
};

const std::array kCatalog{
    EffectInfo{"amplitude_imbalance", "cos channel x (1+alpha); eps ~ (alpha/2) sin 2theta",
               "Hanselman eq. 4-5, Hwang eq. 6, 10, 15-16", kAmplitudeImbalance, true,
               [](const SensorChainConfig& c) { return c.amplitude_imbalance.active(); }},
    EffectInfo{"quadrature", "cos channel cos(theta+beta); eps ~ -(beta/2)(1 - cos 2theta)",
               "Hanselman eq. 6-7 (sign checked: eps = theta - phi)", kQuadrature, true,
               [](const SensorChainConfig& c) { return c.quadrature.active(); }},
    EffectInfo{"offsets", "additive sin/cos offsets; eps ~ o_c sin theta - o_s cos theta", "first-order atan2",
               kOffsets, true, [](const SensorChainConfig& c) { return c.offsets.active(); }},
    EffectInfo{"harmonics",
               "K_0 + K_n {sin, cos}(n theta) on the channels (orders up to k16); "
               "eps ~ -sqrt2 K_0 cos(theta+pi/4) - sum K_n sin((n-1)theta)",
               "Hanselman eq. 8-9", kHarmonics, true,
               [](const SensorChainConfig& c) { return c.harmonics.active(); }},
    EffectInfo{"sampling_skew",
               "cos sampled tau after sin: like quadrature with beta = omega tau on the sampled sin/cos "
               "(not the R/D angle); grows with speed",
               "DESIGN 6, Hanselman eq. 6-7 via beta = omega tau", kSamplingSkew, true,
               [](const SensorChainConfig& c) { return c.sampling_skew.active(); }},
    EffectInfo{"tracking_loop", "type-II R/D loop: error ripple filtered by H(s), lag under acceleration",
               "Hanselman II.A, Hwang Fig. 2", kTrackingLoop, true,
               [](const SensorChainConfig& c) { return c.tracking_loop.active(); }},
    EffectInfo{"quantization", "R/D angle rounded to 2pi/2^rd_bits; uniform +-1/2 LSB", "Hanselman Table I",
               kQuantization, true, [](const SensorChainConfig& c) { return c.quantization.active(); }},
    EffectInfo{"eccentricity",
               "resolver sees theta_m + e sin(theta_m + phase): eps = -p_r e sin(theta_m + phase), 1x mechanical",
               "DESIGN 6", kEccentricity, true, [](const SensorChainConfig& c) { return c.eccentricity.active(); }},
    EffectInfo{"mounting_offset",
               "drive angle = theta_e + theta_0: eps = -(p_r/p) theta_0; steady i_d = -i_q sin theta_0 in the "
               "reference frame",
               "DESIGN 6", kMountingOffset, true,
               [](const SensorChainConfig& c) { return c.mounting_offset.active(); }},
    EffectInfo{"current_offsets",
               "i_a + off_a, i_b + off_b: dq ripple at 1x theta_e of amplitude hypot(off_a, off_b/sqrt3)", "DESIGN 6",
               kCurrentOffsets, true, [](const SensorChainConfig& c) { return c.current_offsets.active(); }},
    EffectInfo{"current_gain_mismatch",
               "i_a (1+gain_a), i_b (1+gain_b): dq ripple at 2x theta_e of amplitude "
               "|I|/2 sqrt((gain_a - gain_b/2)^2 + gain_b^2/12)",
               "DESIGN 6", kCurrentGain, true,
               [](const SensorChainConfig& c) { return c.current_gain_mismatch.active(); }},
    EffectInfo{"dead_time",
               "signature model: 5th/7th current harmonics k_dt |I|, dq ripple at 6x theta_e (2 k_dt i_q on i_d)",
               "DESIGN 6; dead_time.h", kDeadTime, true,
               [](const SensorChainConfig& c) { return c.dead_time.active(); }},
    EffectInfo{"noise", "white noise on sin/cos samples and phase currents; sets the floor", "DESIGN 6", kNoise,
               true, [](const SensorChainConfig& c) { return c.noise.active(); }},
};

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  return s;
}

std::string effect_names(bool implemented_only) {
  std::string out;
  for (const EffectInfo& e : kCatalog) {
    if (implemented_only && !e.implemented) continue;
    if (!out.empty()) out += ", ";
    out += e.name;
  }
  return out;
}

std::string parameter_names(const EffectInfo& e) {
  std::string out;
  for (const EffectParameter& p : e.parameters) {
    if (!out.empty()) out += ", ";
    out += p.name;
  }
  return out;
}

std::string example_spec(const EffectInfo& e) {
  const EffectParameter& p = e.parameters.front();
  const double example = p.integer ? p.max : 0.001;
  return fmt::format("{}:{}={}", e.name, p.name, example);
}

}  // namespace

std::span<const EffectInfo> effect_catalog() { return kCatalog; }

const EffectInfo* find_effect(std::string_view name) {
  for (const EffectInfo& e : kCatalog) {
    if (e.name == name) return &e;
  }
  return nullptr;
}

std::optional<std::string> apply_effect_spec(SensorChainConfig& config, std::string_view spec) {
  const std::string_view whole = trim(spec);
  const std::size_t colon = whole.find(':');
  const std::string_view name = trim(whole.substr(0, colon));
  const EffectInfo* effect = find_effect(name);
  if (effect == nullptr) {
    return fmt::format("effect spec '{}': unknown effect '{}'; valid effects: {} (see --list-effects)", spec, name,
                       effect_names(true));
  }
  if (!effect->implemented) {
    return fmt::format(
        "effect spec '{}': effect '{}' is in the catalog (DESIGN 6) but not implemented in this version; "
        "implemented effects: {}",
        spec, name, effect_names(true));
  }
  if (colon == std::string_view::npos || trim(whole.substr(colon + 1)).empty()) {
    return fmt::format("effect spec '{}': no parameters; write {}:param=value[,param=value] with {} (e.g. {})", spec,
                       name, parameter_names(*effect), example_spec(*effect));
  }
  // Parse everything into a copy first so a bad spec leaves `config` unchanged.
  SensorChainConfig updated = config;
  std::string_view rest = whole.substr(colon + 1);
  while (!rest.empty()) {
    const std::size_t comma = rest.find(',');
    const std::string_view item = trim(rest.substr(0, comma));
    rest = comma == std::string_view::npos ? std::string_view{} : rest.substr(comma + 1);
    const std::size_t eq = item.find('=');
    if (eq == std::string_view::npos) {
      return fmt::format("effect spec '{}': '{}' is not param=value; parameters of {}: {}", spec, item, name,
                         parameter_names(*effect));
    }
    const std::string_view pname = trim(item.substr(0, eq));
    const std::string_view text = trim(item.substr(eq + 1));
    const EffectParameter* param = nullptr;
    for (const EffectParameter& p : effect->parameters) {
      if (p.name == pname) param = &p;
    }
    if (param == nullptr) {
      return fmt::format("effect spec '{}': effect '{}' has no parameter '{}'; valid parameters: {}", spec, name,
                         pname, parameter_names(*effect));
    }
    double value = 0.0;
    const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
    if (ec != std::errc{} || end != text.data() + text.size() || !std::isfinite(value)) {
      return fmt::format("effect spec '{}': parameter '{}' of {} needs a number {}, got '{}'", spec, pname, name,
                         param->unit, text);
    }
    if (value < param->min || value > param->max || (param->integer && value != std::round(value))) {
      return fmt::format("effect spec '{}': parameter '{}' of {} must be {} in [{}, {}] {}, got {}", spec, pname,
                         name, param->integer ? "an integer" : "a number", param->min, param->max, param->unit,
                         text);
    }
    param->set(updated, value);
  }
  config = updated;
  return std::nullopt;
}

std::string format_effect_catalog() {
  std::string out = "Effect catalog (DESIGN 6). Spec: effect:param=value[,param=value...]\n";
  for (const EffectInfo& e : kCatalog) {
    out += fmt::format("\n  {:<22}{}{}\n  {:<22}source: {}\n", e.name, e.description,
                       e.implemented ? "" : "  (not implemented yet)", "", e.source);
    for (const EffectParameter& p : e.parameters) {
      if (!p.listed) continue;
      out += fmt::format("      {:<9}{:<26}{}, in [{}, {}]\n", p.name, p.unit, p.description, p.min, p.max);
    }
  }
  return out;
}

std::vector<EffectValues> active_effect_values(const SensorChainConfig& config) {
  std::vector<EffectValues> out;
  for (const EffectInfo& e : kCatalog) {
    if (!e.implemented || e.active == nullptr || !e.active(config)) continue;
    EffectValues values{e.name, {}};
    const bool skip_zero = e.name == "harmonics";
    for (const EffectParameter& p : e.parameters) {
      const double v = p.get(config);
      if (skip_zero && v == 0.0) continue;
      values.parameters.emplace_back(p.name, v);
    }
    out.push_back(std::move(values));
  }
  return out;
}

}  // namespace resolver
