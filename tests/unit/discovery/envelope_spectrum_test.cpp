// The fit's envelope model is exact at real-sensor magnitudes (issue 21): the joint
// series of gain, quadrature, offsets and winding harmonics equals the simulator's
// forward chain (atan2 and hypot of its envelopes) at any angle, each column equals the
// chain's finite-difference derivative there, and a Design's prediction and Jacobian
// carry them. Magnitudes: alpha 0.15, beta 0.05 rad, offsets 0.05, harmonics 0.05 with
// their own phase (the "realistic" set), and the catalog's small defaults.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "daemon/core/angles.h"
#include "daemon/core/effects/chain_values.h"
#include "daemon/core/effects/forward_chain.h"
#include "daemon/core/effects/registry.h"
#include "daemon/core/model/design.h"
#include "daemon/core/model/envelope_spectrum.h"
#include "daemon/core/model/model_spec.h"
#include "tests/unit/discovery/envelope_members.h"

namespace resolver {
namespace {

struct Setting {
  const char* name;
  std::vector<std::string> specs;  // resolver-sim style: "effect:param=value,..."
};

const std::vector<Setting>& settings() {
  static const std::vector<Setting> s{
      {"real magnitudes",
       {"amplitude_imbalance:alpha=0.15", "quadrature:beta=0.05", "offsets:o_s=0.05,o_c=-0.03",
        "harmonics:k2=0.05,k2_q=0.02,k3_opp=0.03,k3_opp_q=-0.04"}},
      {"small defaults", {"amplitude_imbalance:alpha=0.003", "harmonics:k3=0.001"}},
      {"negative gain, large quadrature", {"amplitude_imbalance:alpha=-0.13", "quadrature:beta=-0.08"}},
  };
  return s;
}

/// The members of the forward chain's envelope effects at the setting's values.
struct Members : test::EnvelopeMembers {
  explicit Members(const Setting& s) : EnvelopeMembers(s.specs) {}
};

/// The simulator's envelopes of the seen angle (forward_chain.h), as the truth.
SinCos chain_envelopes(const ChainValues& values, double phi) {
  const ForwardChain chain(values, 3, 3);
  return chain.envelopes(phi);
}

TEST(EnvelopeSpectrum, SeriesIsTheForwardChainThroughAtan2AndHypot) {
  for (const Setting& s : settings()) {
    const Members m(s);
    const EnvelopeSeries series = envelope_series(m.members);
    AngleBasis basis;
    for (int j = 0; j < 97; ++j) {
      SignatureRow row;
      row.theta = 0.37 + 2.0 * std::numbers::pi * j / 97.0;
      basis.set(row, BasisTransform{});
      const SinCos env = chain_envelopes(m.values, row.theta);
      const double e = wrap_pi(row.theta - std::atan2(env.s, env.c));
      const double r = std::hypot(env.s, env.c) - 1.0;
      const SignalValues got = series.at(basis);
      // The series is exact to its truncation (kDropBelow = 1e-13 per order) and the
      // basis's rotation recurrence (~order x 1e-16): 1e-11 is far below any floor.
      EXPECT_NEAR(got.sa, e, 1e-11) << s.name << " theta " << row.theta;
      EXPECT_NEAR(got.rd, e, 1e-11) << s.name << " (ideal converter: the R/D angle's error is the same)";
      EXPECT_NEAR(got.sr, r, 1e-11) << s.name;
    }
  }
}

TEST(EnvelopeSpectrum, ColumnsAreTheChainsDerivativesAtRealMagnitudes) {
  for (const Setting& s : settings()) {
    const Members m(s);
    AngleBasis basis;
    for (std::size_t member = 0; member < m.members.size(); ++member) {
      const Effect& effect = *m.members[member].effect;
      for (std::size_t p = 0; p < effect.params().size(); ++p) {
        const std::string name = std::string(effect.name()) + "." + std::string(effect.params()[p].name);
        const EnvelopeSeries d = envelope_derivative_series(m.members, member, p);
        // Central differences of the chain's own envelopes through atan2 / hypot.
        const double h = 1e-6;
        ChainValues up = m.values, down = m.values;
        const double v = m.members[member].values[p];
        up.set(effect.name(), effect.params()[p].name, v + h);
        down.set(effect.name(), effect.params()[p].name, v - h);
        for (int j = 0; j < 31; ++j) {
          SignatureRow row;
          row.theta = 0.11 + 2.0 * std::numbers::pi * j / 31.0;
          basis.set(row, BasisTransform{});
          const SinCos a = chain_envelopes(up, row.theta), b = chain_envelopes(down, row.theta);
          const double de = wrap_pi(std::atan2(b.s, b.c) - std::atan2(a.s, a.c)) / (2.0 * h);
          const double dr = (std::hypot(a.s, a.c) - std::hypot(b.s, b.c)) / (2.0 * h);
          const SignalValues got = d.at(basis);
          // Truncation h^2 f''' ~ 1e-12 and rounding 1e-16 / h ~ 1e-10 of the column (~1).
          EXPECT_NEAR(got.sa, de, 1e-8) << s.name << ": " << name << " at theta " << row.theta;
          EXPECT_NEAR(got.sr, dr, 1e-8) << s.name << ": " << name << " at theta " << row.theta;
        }
      }
    }
  }
}

TEST(EnvelopeSpectrum, ADesignPredictsExactlyAndTurnsWithTheFrameShift) {
  const Setting& s = settings().front();
  const Members m(s);
  const ModelSpec spec = ModelSpec::parse(std::vector<std::string>{"amplitude_imbalance", "quadrature", "offsets",
                                                                   "harmonics(k2,k2_q,k3_opp,k3_opp_q)"});
  std::vector<std::vector<double>> values;
  for (const ModelTerm& t : spec.terms) {
    const Values v = m.values.of(*t.effect);
    values.emplace_back(v.begin(), v.end());
  }
  Design design(spec, values, {});
  AngleBasis basis;
  for (double shift : {0.0, 1.3, -2.9}) {
    design.set_frame_shift(shift);
    for (int j = 0; j < 13; ++j) {
      FitRow row;
      row.sig.theta = 0.2 + 0.5 * j;
      const SignalValues got = design.predict(row, basis);
      // The sensor's angle is the row's plus the shift; its error and the constant -shift.
      const double seen = row.sig.theta + shift;
      const SinCos env = chain_envelopes(m.values, seen);
      EXPECT_NEAR(got.sa, wrap_pi(seen - std::atan2(env.s, env.c)) - shift, 1e-11) << shift;
      EXPECT_NEAR(got.sr, std::hypot(env.s, env.c) - 1.0, 1e-11) << shift;
    }
  }
}

}  // namespace
}  // namespace resolver
