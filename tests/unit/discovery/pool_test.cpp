// Pooled fits (pool.h): joining prepared logs, and naming the log whose own fit
// disagrees with the others. The pooled fit itself, end to end, is
// tests/integration/test_pooled_fit.py.
#include <gtest/gtest.h>

#include <stdexcept>
#include <string>
#include <vector>

#include "daemon/core/discovery/pool.h"

namespace resolver {
namespace {

ModelFit fit_with(double value, double se) {
  ModelFit f;
  f.params.push_back({"amplitude_imbalance.alpha", value, se, "[1]"});
  return f;
}

std::vector<std::string> flagged(const std::vector<PoolDisagreement>& d) {
  std::vector<std::string> out;
  for (const PoolDisagreement& x : d) {
    if (std::abs(x.z) > kPoolDisagreementZ) out.push_back(x.log);
  }
  return out;
}

TEST(PoolComparison, TheOddLogIsNamedAloneAndDoesNotMakeTheOthersOdd) {
  const ModelFit pooled = fit_with(1.05, 0.005);
  const std::vector<ModelFit> alone{fit_with(1.0, 0.01), fit_with(1.01, 0.01), fit_with(0.99, 0.01), fit_with(1.2, 0.01)};
  const auto d = compare_with_pool(pooled, alone, {"a", "b", "c", "odd"});
  EXPECT_EQ(flagged(d), std::vector<std::string>{"odd"});
  ASSERT_FALSE(d.empty());
  EXPECT_EQ(d.front().log, "odd");
  // Compared with the three that agree: their mean 1.0 +- 0.01/sqrt(3).
  EXPECT_NEAR(d.front().others, 1.0, 1e-12);
  EXPECT_NEAR(d.front().z, 0.2 / std::sqrt(0.01 * 0.01 + 0.01 * 0.01 / 3.0), 1e-9);
}

TEST(PoolComparison, TwoLogsThatDifferAreBothNamed) {
  const auto d = compare_with_pool(fit_with(1.0, 0.005), {fit_with(1.0, 0.01), fit_with(1.1, 0.01)}, {"a", "b"});
  EXPECT_EQ(flagged(d).size(), 2U);
}

TEST(PoolComparison, LogsThatAgreeWithinTheirErrorsAreNotNamed) {
  const auto d = compare_with_pool(fit_with(1.0, 0.005),
                                   {fit_with(1.0, 0.01), fit_with(1.02, 0.01), fit_with(0.985, 0.01)}, {"a", "b", "c"});
  EXPECT_TRUE(flagged(d).empty());
  EXPECT_EQ(d.size(), 3U);
}

TEST(PoolComparison, APhaseIsComparedOnTheCircle) {
  // Eccentricity's phase near +-pi: 3.13 and -3.13 rad are 0.023 rad apart (z ~ 1.6),
  // not 6.26 (z ~ 440, a false "changed between runs").
  const auto phase = [](double v) {
    ModelFit f;
    f.params.push_back({"eccentricity.phase", v, 0.01, "[rad]"});
    return f;
  };
  const auto d = compare_with_pool(phase(3.14), {phase(3.13), phase(-3.13), phase(3.135)}, {"a", "b", "c"});
  EXPECT_TRUE(flagged(d).empty());
  for (const PoolDisagreement& x : d) EXPECT_LT(std::abs(x.z), 2.0) << x.log;
}

TEST(PoolComparison, ALogWhoseOwnFitFailedIsLeftOut) {
  const auto d = compare_with_pool(fit_with(1.0, 0.005), {fit_with(1.0, 0.01), ModelFit{}, fit_with(1.0, 0.01)},
                                   {"a", "failed", "c"});
  for (const PoolDisagreement& x : d) EXPECT_NE(x.log, "failed");
  EXPECT_EQ(d.size(), 2U);
}

PreparedLog log_of(int rows, double period, bool sincos = true) {
  PreparedLog l;
  l.rd = true;
  l.sincos = sincos;
  l.reference = true;
  l.sample_period = period;
  l.amplitude = 1000.0;
  l.samples_in = rows;
  l.fold_rule = "alternate mechanical revolutions";
  l.floors.rd.chosen = 1e-4;
  for (int i = 0; i < rows; ++i) {
    FitRow r;
    r.sig.t = i * period;
    r.block = i / 10;
    r.flags = FitRow::kHasRd | FitRow::kMoving;
    l.rows.push_back(r);
    l.sample_of_row.push_back(static_cast<std::size_t>(i));
  }
  return l;
}

TEST(PoolLogs, RowsKeepTheirLogAndTimeRunsOnWithAGap) {
  const PreparedLog pool = pool_logs({log_of(100, 1e-3), log_of(50, 1e-3)}, {"a", "b"});
  ASSERT_EQ(pool.rows.size(), 150U);
  EXPECT_EQ(pool.part_count(), 2);
  EXPECT_EQ(pool.rows[99].part, 0);
  EXPECT_EQ(pool.rows[100].part, 1);
  // No history, delay or whiteness lag reaches across: a gap of many sample periods.
  EXPECT_GT(pool.rows[100].sig.t - pool.rows[99].sig.t, 1000 * 1e-3);
  // Revolution blocks are each log's own (robust errors count them apart).
  EXPECT_GT(pool.rows[100].block, pool.rows[99].block);
  EXPECT_EQ(pool.sample_of_row[100], 100U);
  EXPECT_EQ(pool.samples_in, 150);
}

TEST(PoolLogs, LogsOfAnotherLayoutOrBenchAreRefusedByName) {
  try {
    (void)pool_logs({log_of(10, 1e-3), log_of(10, 1e-3, false)}, {"a.log", "b.log"});
    FAIL() << "expected a refusal";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("b.log lacks sin/cos"), std::string::npos) << e.what();
  }
  PreparedLog other = log_of(10, 1e-3);
  other.p_r = 4;
  EXPECT_THROW((void)pool_logs({log_of(10, 1e-3), other}, {"a", "b"}), std::invalid_argument);
  EXPECT_THROW((void)pool_logs({log_of(10, 1e-3)}, {"a"}), std::invalid_argument);
}

TEST(PoolLogs, TheFloorIsTheRowsWeightedPooledVariance) {
  PreparedLog a = log_of(300, 1e-3), b = log_of(100, 1e-3);
  a.floors.rd.chosen = 1e-4;
  b.floors.rd.chosen = 2e-4;
  const PreparedLog pool = pool_logs({a, b}, {"a", "b"});
  EXPECT_NEAR(pool.floors.rd.chosen, std::sqrt((300 * 1e-8 + 100 * 4e-8) / 400.0), 1e-12);
}

}  // namespace
}  // namespace resolver
