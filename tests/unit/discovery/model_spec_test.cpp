// Effect references: a misspelt effect or parameter is refused with the closest
// valid name as a "did you mean" hint (resolver-model --effects, [model] effects).
#include <gtest/gtest.h>

#include <stdexcept>
#include <string>
#include <vector>

#include "daemon/core/model/custom_effect.h"
#include "daemon/core/model/model_spec.h"

namespace resolver {
namespace {

std::string parse_error(const std::string& reference) {
  try {
    (void)ModelSpec::parse(std::vector<std::string>{reference});
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "(accepted)";
}

TEST(ClosestName, TyposFindTheName) {
  const std::vector<std::string> names{"amplitude_imbalance", "quadrature", "offsets", "delay", "dead_time"};
  EXPECT_EQ(closest_name("amplitude_imbalanse", names), "amplitude_imbalance");  // replace
  EXPECT_EQ(closest_name("amplitude_imbalnce", names), "amplitude_imbalance");   // delete
  EXPECT_EQ(closest_name("amplitude__imbalance", names), "amplitude_imbalance"); // insert
  EXPECT_EQ(closest_name("delya", names), "delay");                              // swap of neighbours
  EXPECT_EQ(closest_name("Dead_Time", names), "dead_time");                      // case
  EXPECT_EQ(closest_name("quadratur", names), "quadrature");
  EXPECT_EQ(closest_name("ofsets", names), "offsets");
}

TEST(ClosestName, FarNamesGetNoHint) {
  const std::vector<std::string> names{"amplitude_imbalance", "delay", "dead_time", "backlash"};
  EXPECT_EQ(closest_name("nope", names), "");
  EXPECT_EQ(closest_name("", names), "");
  EXPECT_EQ(closest_name("x", names), "");
  EXPECT_EQ(closest_name("dly", names), "");  // two edits in a 3-letter name is a guess, not a typo
  EXPECT_EQ(closest_name("amplitude", names), "");
  EXPECT_EQ(closest_name("delay", std::vector<std::string>{}), "");
}

TEST(ClosestName, TheNearestWins) {
  const std::vector<std::string> names{"harmonics", "mechanical_harmonics"};
  EXPECT_EQ(closest_name("harmonic", names), "harmonics");
  EXPECT_EQ(closest_name("mechanical_harmonic", names), "mechanical_harmonics");
}

TEST(ModelSpecParse, UnknownEffectNamesTheClosest) {
  const std::string e = parse_error("amplitude_imbalanse");
  EXPECT_NE(e.find("'amplitude_imbalanse' is not a fittable catalog effect"), std::string::npos) << e;
  EXPECT_NE(e.find("(did you mean 'amplitude_imbalance'?); one of: amplitude_imbalance"), std::string::npos) << e;
  const std::string far = parse_error("nope");
  EXPECT_EQ(far.find("did you mean"), std::string::npos) << far;
  EXPECT_NE(far.find("'nope' is not a fittable catalog effect or a [[model.custom]] name; one of: amplitude_imbalance"),
            std::string::npos)
      << far;
}

TEST(ModelSpecParse, UnknownParameterNamesTheClosest) {
  const std::string e = parse_error("harmonics(k3,k55)");
  EXPECT_NE(e.find("harmonics has no parameter 'k55' (did you mean"), std::string::npos) << e;
  EXPECT_EQ(parse_error("amplitude_imbalance"), "(accepted)");
}

}  // namespace
}  // namespace resolver

namespace resolver {
namespace {

// Issue 25: a term that is inf or nan everywhere, 1/(theta-theta), was taken and the
// fit then said "not separable"; it is refused at load, naming the block and the term.
std::string custom_error(const std::string& term) {
  try {
    CustomEffectSpec spec;
    spec.name = "broken";
    spec.terms = {"t", term};
    spec.origin = "x.toml [[model.custom]] #1";
    const CustomEffect effect(spec);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

TEST(CustomEffect, ATermThatIsNotFiniteAnywhereIsRefusedNamingIt) {
  const std::string e = custom_error("1/(theta-theta)");
  EXPECT_NE(e.find("x.toml [[model.custom]] #1 custom effect 'broken', term 2 \"1/(theta-theta)\": evaluates to inf at "
                   "every angle, speed and time tried"),
            std::string::npos)
      << e;
  EXPECT_NE(e.find("division by zero"), std::string::npos) << e;
  EXPECT_NE(custom_error("sqrt(-1-abs(omega))").find("evaluates to nan"), std::string::npos);
  EXPECT_NE(custom_error("-1/(t-t)").find("evaluates to -inf"), std::string::npos);
  // Controls: a pole at one angle, a root of the speed, a log of the time are finite somewhere.
  EXPECT_EQ(custom_error("1/sin(theta)"), "");
  EXPECT_EQ(custom_error("sqrt(omega)"), "");
  EXPECT_EQ(custom_error("ln(t)"), "");
}

}  // namespace
}  // namespace resolver
