// A candidate that only moves the seen angle (eccentricity, mechanical harmonics, a
// mounting offset, a play) gets its column from the model's slope in the shift times
// the candidate's shift plus its own signature (Design::evaluate_row), not from a whole
// prediction per column. Checked against that whole prediction: the model at real
// magnitudes (a 10 % imbalance, 20 mrad quadrature, a 2 % third harmonic: the winding
// errors the shift turns are large) with the candidate added at a small value h.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "daemon/core/model/design.h"
#include "daemon/core/model/model.h"
#include "daemon/core/model/model_spec.h"

namespace resolver {
namespace {

const std::vector<std::string> kModel{"amplitude_imbalance", "quadrature", "harmonics(k3)"};

std::vector<std::vector<double>> model_values(const ModelSpec& spec) {
  Model m(spec, 3, 3);
  m.set("amplitude_imbalance.alpha", 0.1);
  m.set("quadrature.beta", 0.02);
  m.set("harmonics.k3", 0.02);
  return m.values();
}

FitRow row_at(double theta) {
  FitRow r;
  r.sig.t = 1.0;
  r.sig.theta = theta;
  r.sig.theta_m = theta / 3.0;
  r.sig.omega = 60.0;
  r.sig.p_r = 3;
  r.sig.p = 3;
  r.flags = FitRow::kHasRd | FitRow::kHasSc | FitRow::kMoving;
  return r;
}

void expect_column_is_the_whole_predictions(const std::string& candidate) {
  const ModelSpec model = ModelSpec::parse(kModel);
  const ModelTerm term = ModelSpec::parse(std::vector<std::string>{candidate}).terms.front();
  Design d(model, model_values(model), {});
  d.add_candidate(term);
  // The candidate at h in its first parameter, as a model term: the whole prediction.
  ModelSpec with = model;
  with.add(term);
  std::vector<std::vector<double>> values = model_values(model);
  std::vector<double> moved = Model(ModelSpec::parse(std::vector<std::string>{candidate}), 3, 3).values().front();
  const double h = 1e-6;
  moved[static_cast<std::size_t>(term.params.front())] = h;
  values.push_back(moved);
  const Design at_h(with, values, {});
  const Design at_zero(model, model_values(model), {});
  AngleBasis basis;
  RowJacobian jac;
  SignalValues pred;
  for (const double theta : {0.3, 1.7, 2.9, 4.4, 5.8}) {
    const FitRow r = row_at(theta);
    d.evaluate(r, basis, pred, jac);
    const SignalValues a = at_h.predict(r, basis), b = at_zero.predict(r, basis);
    const int col = d.term_column(d.terms().size() - 1);
    // Both first order in h: they differ by O(h) of a column of order 1 (1e-6), far
    // below what a fit resolves (columns meet noise floors of 1e-5 rad and more).
    EXPECT_NEAR(jac.rd[col], (a.rd - b.rd) / h, 2e-5) << candidate << " rd at " << theta;
    EXPECT_NEAR(jac.sa[col], (a.sa - b.sa) / h, 2e-5) << candidate << " sa at " << theta;
    EXPECT_NEAR(jac.sr[col], (a.sr - b.sr) / h, 2e-5) << candidate << " sr at " << theta;
  }
}

TEST(DesignShiftColumn, EccentricityIsTheWholePrediction) { expect_column_is_the_whole_predictions("eccentricity"); }
TEST(DesignShiftColumn, MechanicalHarmonicIsTheWholePrediction) {
  expect_column_is_the_whole_predictions("mechanical_harmonics(a2,b2)");
}
TEST(DesignShiftColumn, MountingOffsetIsTheWholePrediction) {
  expect_column_is_the_whole_predictions("mounting_offset");
}
TEST(DesignShiftColumn, BacklashIsTheWholePrediction) { expect_column_is_the_whole_predictions("backlash"); }

}  // namespace
}  // namespace resolver
