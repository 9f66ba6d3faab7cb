// ParamSet (param_set.h): an effect's parameters are written once, in its ParamInfo
// list, and read by name through the type generated from it. These tests hold the
// "once" to account: the typed access and the registry share the one list object,
// and every forward hook accepts every value the list allows, so a second range
// (a struct's comment, a hook's own check, a clamp that throws) cannot disagree
// with the list unnoticed. A name the list lacks is a compile error (ParamKey's
// consteval constructor), which a test cannot show at run time.
#include <gtest/gtest.h>

#include <cmath>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "daemon/core/angles.h"
#include "daemon/core/effects/amplitude_imbalance.h"
#include "daemon/core/effects/chain_values.h"
#include "daemon/core/effects/current_gain_mismatch.h"
#include "daemon/core/effects/current_offsets.h"
#include "daemon/core/effects/dead_time.h"
#include "daemon/core/effects/eccentricity.h"
#include "daemon/core/effects/effect.h"
#include "daemon/core/effects/envelope_drift.h"
#include "daemon/core/effects/forward_chain.h"
#include "daemon/core/effects/harmonics.h"
#include "daemon/core/effects/mounting_offset.h"
#include "daemon/core/effects/noise.h"
#include "daemon/core/effects/offsets.h"
#include "daemon/core/effects/quadrature.h"
#include "daemon/core/effects/quantization.h"
#include "daemon/core/effects/registry.h"
#include "daemon/core/effects/sampling_skew.h"

namespace resolver {
namespace {

TEST(ParamSet, StartsNeutralAndSetsByName) {
  const QuantizationParams ideal;
  EXPECT_EQ(ideal["rd_bits"], kRdFieldBits);  // rd_bits' neutral value is not 0
  EXPECT_FALSE(ideal.active());
  const OffsetsParams p{{"o_c", -0.002}};
  EXPECT_EQ(p["o_s"], 0.0);
  EXPECT_EQ(p["o_c"], -0.002);
  EXPECT_TRUE(p.active());
  // The values in the list's order, as the registry hands them to the hooks.
  ASSERT_EQ(p.values().size(), kOffsetsParams.size());
  EXPECT_EQ(p.values()[OffsetsParams::index("o_c")], -0.002);
  EXPECT_EQ(OffsetsParams(p.values())["o_c"], -0.002);
  EXPECT_EQ(OffsetsParams::info("o_s").unit, "[fraction of amplitude]");
}

TEST(ParamSet, RefusesValuesOfAnotherLength) {
  const std::vector<double> three{0.1, 0.2, 0.3};
  EXPECT_THROW((void)OffsetsParams(std::span<const double>(three)), std::invalid_argument);
}

TEST(ParamSet, HarmonicKeysNameTheirOrder) {
  for (int n = 2; n <= kHarmonicsMaxOrder; ++n) {
    const HarmonicKeys& k = harmonic_keys(n);
    const std::string kn = "k" + std::to_string(n);
    EXPECT_EQ(k.same.info().name, kn);
    EXPECT_EQ(k.opp.info().name, kn + "_opp");
    EXPECT_EQ(k.same_q.info().name, kn + "_q");
    EXPECT_EQ(k.opp_q.info().name, kn + "_opp_q");
  }
}

/// The registry's list of `effect` is the very object its typed access is generated from.
template <const auto& List>
void expect_registry_list(const Effect& effect) {
  EXPECT_EQ(effect.params().data(), List.data()) << effect.name() << ": a second list beside the typed one";
  EXPECT_EQ(effect.params().size(), List.size()) << effect.name();
}

TEST(ParamSet, TypedListsAreTheRegistrysLists) {
  expect_registry_list<kAmplitudeImbalanceParams>(amplitude_imbalance_effect());
  expect_registry_list<kQuadratureParams>(quadrature_effect());
  expect_registry_list<kOffsetsParams>(offsets_effect());
  expect_registry_list<kHarmonicsParams>(harmonics_effect());
  expect_registry_list<kEnvelopeDriftParams>(envelope_drift_effect());
  expect_registry_list<kSamplingSkewParams>(sampling_skew_effect());
  expect_registry_list<kQuantizationParams>(quantization_effect());
  expect_registry_list<kEccentricityParams>(eccentricity_effect());
  expect_registry_list<kMountingOffsetParams>(mounting_offset_effect());
  expect_registry_list<kCurrentOffsetsParams>(current_offsets_effect());
  expect_registry_list<kCurrentGainMismatchParams>(current_gain_mismatch_effect());
  expect_registry_list<kDeadTimeParams>(dead_time_effect());
  expect_registry_list<kNoiseParams>(noise_effect());
}

bool finite(const SinCos& s) { return std::isfinite(s.s) && std::isfinite(s.c); }
bool finite(const PhaseCurrents& i) { return std::isfinite(i.a) && std::isfinite(i.b) && std::isfinite(i.c); }

/// Runs every forward hook of a chain over one mechanical turn; false at the first non-finite value.
bool forward_hooks_finite(ForwardChain& chain) {
  constexpr int kSteps = 64;
  constexpr double kOmegaM = 100.0;  // [rad/s] mechanical
  for (int k = 0; k <= kSteps; ++k) {
    const double theta_m = kTwoPi * k / kSteps;
    const double theta = chain.resolver_angle(theta_m, kOmegaM, true);
    const double theta_e = 3.0 * theta_m;
    const PhaseCurrents actual = chain.machine_currents(1.0, 10.0, theta_e);
    if (!std::isfinite(theta) || !finite(chain.envelopes(theta, 0.01 * k)) || !finite(actual) ||
        !finite(chain.measured_currents(actual, theta_e))) {
      return false;
    }
  }
  const ChannelTiming& t = chain.timing();
  const Impairments& imp = chain.impairments();
  return std::isfinite(chain.time_shift()) && std::isfinite(t.converter_cos_dt) && std::isfinite(t.dsp_cos_dt) &&
         std::isfinite(chain.converter().loop["omega_n"]) && std::isfinite(imp.sigma_sc) && std::isfinite(imp.sigma_i);
}

// Issue 22: a range is written once, in the list. Every end of it, the others
// neutral, passes the chain's checks (ChainValues::set, each effect's validate())
// and every forward hook gives finite values there: a second, narrower range in a
// forward function, a hook or a struct would refuse one of them.
TEST(ParamSet, ForwardHooksAcceptEveryListedRangeEnd) {
  for (const Effect* e : effect_registry()) {
    for (const ParamInfo& p : e->params()) {
      for (const double x : {p.min, p.max}) {
        ChainValues values;
        const std::string what = std::string(e->name()) + "." + std::string(p.name) + " = " + std::to_string(x);
        try {
          values.set(e->name(), p.name, x);
          ForwardChain chain(values, 3, 3);
          EXPECT_TRUE(forward_hooks_finite(chain)) << what << " is in its listed range but gives non-finite values";
        } catch (const std::exception& ex) {
          ADD_FAILURE() << what << " is in its listed range but refused: " << ex.what();
        }
      }
    }
  }
}

}  // namespace
}  // namespace resolver
