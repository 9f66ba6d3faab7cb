// A run's estimate from its windows (run_estimate.h): the inverse-variance mean and
// its error, formal with few windows, from their scatter with many.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "daemon/core/estimation/estimator_models.h"
#include "daemon/core/model/run_estimate.h"

namespace resolver {
namespace {

double alpha_of(const Model& m) { return m.parameters().at(0).value; }
double se_of(const Model& m) { return m.parameters().at(0).std_error; }

TEST(RunEstimate, TwoWindowsGiveTheInverseVarianceMean) {
  RunEstimate run;
  run.add(hwang_model(1.0e-3, 1e-5, 3, 3), 1000, 16.0);
  run.add(hwang_model(2.0e-3, 2e-5, 3, 3), 1000, 16.0);
  // weights 1e10 and 2.5e9: (1e-3 * 1e10 + 2e-3 * 2.5e9) / 1.25e10 = 1.2e-3
  EXPECT_NEAR(alpha_of(run.combined()), 1.2e-3, 1e-15);
  EXPECT_NEAR(se_of(run.combined()), 1.0 / std::sqrt(1.25e10), 1e-15);
  EXPECT_EQ(run.windows(), 2);
  EXPECT_EQ(run.samples(), 2000);
  EXPECT_DOUBLE_EQ(run.revolutions(), 32.0);
  EXPECT_NE(run.basis().find("formal"), std::string::npos) << run.basis();
}

TEST(RunEstimate, ManyWindowsTakeTheErrorFromTheirScatter) {
  // Eight windows that scatter 10x more than their own errors say (a sensor that
  // drifts, or errors that understate): the combined error follows the scatter.
  RunEstimate run;
  const std::vector<double> x{1.0, -1.0, 1.0, -1.0, 1.0, -1.0, 1.0, -1.0};
  for (double v : x) run.add(hwang_model(3e-3 + 1e-5 * v, 1e-6, 3, 3), 100, 16.0);
  EXPECT_NEAR(alpha_of(run.combined()), 3e-3, 1e-15);
  // chi2 = 8 * (1e-5 / 1e-6)^2 = 800; se^2 = chi2 / ((K - 1) sum w) = 800 / (7 * 8e12)
  EXPECT_NEAR(se_of(run.combined()), std::sqrt(800.0 / (7.0 * 8e12)), 1e-12);
  EXPECT_GT(se_of(run.combined()), 5.0 * 1e-6 / std::sqrt(8.0));  // wider than formal
  EXPECT_NE(run.basis().find("window-to-window spread of 8 windows"), std::string::npos) << run.basis();
}

TEST(RunEstimate, AnotherModelStartsAgain) {
  RunEstimate run;
  run.add(hwang_model(1e-3, 1e-5, 3, 3), 100, 16.0);
  run.add(hwang_model(1e-3, 1e-5, 3, 3), 100, 16.0);
  SinCosFit f;
  f.alpha = {5e-3, 1e-5};
  run.add(sincos_model(f, 3, 3), 100, 16.0);  // a reload changed the effects
  EXPECT_EQ(run.windows(), 1);
  EXPECT_NEAR(alpha_of(run.combined()), 5e-3, 1e-15);
  run.add(hwang_model(1e-3, 1e-5, 3, 4), 100, 16.0);  // other pole pairs
  EXPECT_EQ(run.windows(), 1);
}

TEST(RunEstimate, WindowsWithoutAnErrorGiveThePlainMeanAndNoError) {
  RunEstimate run;
  run.add(hwang_model(1e-3, std::nan(""), 3, 3), 100, 16.0);
  run.add(hwang_model(3e-3, 0.0, 3, 3), 100, 16.0);
  EXPECT_NEAR(alpha_of(run.combined()), 2e-3, 1e-15);
  EXPECT_TRUE(std::isnan(se_of(run.combined())));
}

}  // namespace
}  // namespace resolver
