// Passes over many rows on several threads (row_blocks.h): every row once, the blocks
// added in order, and a pass's sums the same to the last bit on any number of threads.
#include <gtest/gtest.h>

#include <cmath>
#include <cstddef>
#include <mutex>
#include <stdexcept>
#include <string>
#include <vector>

#include "daemon/core/model/design.h"
#include "daemon/core/model/least_squares.h"
#include "daemon/core/model/model.h"
#include "daemon/core/model/model_spec.h"
#include "daemon/core/model/row_blocks.h"

namespace resolver {
namespace {

/// Sets the pass threads for one test and restores one thread after it.
struct Threads {
  explicit Threads(int n) { set_pass_threads(n); }
  ~Threads() { set_pass_threads(1); }
  Threads(const Threads&) = delete;
  Threads& operator=(const Threads&) = delete;
};

TEST(RowBlocks, EveryRowOnceAndTheBlocksAddedInOrder) {
  for (const int threads : {1, 2, 3, 8}) {
    const Threads use(threads);
    for (const std::size_t rows : {std::size_t{0}, std::size_t{1}, kRowBlock, kRowBlock + 1, 7 * kRowBlock / 2}) {
      std::vector<int> seen(rows, 0);
      const int workers = row_block_workers(rows);
      std::vector<std::size_t> from_of(static_cast<std::size_t>(workers));
      std::vector<std::size_t> added;
      over_row_blocks(
          rows, workers,
          [&](int w, std::size_t from, std::size_t to) {
            from_of[static_cast<std::size_t>(w)] = from;
            for (std::size_t i = from; i < to; ++i) ++seen[i];  // disjoint blocks: no two threads share a row
          },
          [&](int w) { added.push_back(from_of[static_cast<std::size_t>(w)]); });
      for (std::size_t i = 0; i < rows; ++i) ASSERT_EQ(seen[i], 1) << "row " << i << " of " << rows << ", " << threads;
      for (std::size_t k = 0; k < added.size(); ++k) EXPECT_EQ(added[k], k * kRowBlock) << threads << " threads";
      EXPECT_EQ(added.size(), (rows + kRowBlock - 1) / kRowBlock);
    }
  }
}

TEST(RowBlocks, ABlocksExceptionReachesTheCaller) {
  const Threads use(2);
  EXPECT_THROW(over_row_blocks(
                   3 * kRowBlock, 2,
                   [](int, std::size_t from, std::size_t) {
                     if (from == kRowBlock) throw std::runtime_error("block 1");
                   },
                   [](int) {}),
               std::runtime_error);
}

/// 100,000 rows of a 10 kHz log at 600 r/min (p_r = 3) with a model at real magnitudes
/// and a candidate's columns: what a pass of explain sums.
std::vector<FitRow> rows_of_a_log() {
  std::vector<FitRow> rows(100000);
  for (std::size_t i = 0; i < rows.size(); ++i) {
    FitRow& r = rows[i];
    const double t = 1e-4 * static_cast<double>(i);
    r.sig.t = t;
    r.sig.theta_m = 62.8 * t;
    r.sig.theta = 3.0 * r.sig.theta_m;
    r.sig.omega = 3.0 * 62.8;
    r.sig.p_r = 3;
    r.sig.p = 3;
    r.flags = FitRow::kHasRd | FitRow::kHasSc | FitRow::kMoving | (i % 2 == 0 ? FitRow::kFoldB : 0);
    // Some structure the model does not have, so the residuals are not zero.
    r.y_rd = 1e-3 * std::sin(2.0 * r.sig.theta + 0.4);
    r.y_sa = 1e-3 * std::cos(3.0 * r.sig.theta);
    r.y_sr = 2e-3 * std::sin(r.sig.theta_m);
  }
  return rows;
}

PassStatistics pass(const Design& d, const std::vector<FitRow>& rows, int threads) {
  const Threads use(threads);
  PassStatistics s;
  accumulate(d, rows, GroupFloors{.rd = 1e-4, .sc = 1e-4, .cur = 0.0}, s);
  return s;
}

TEST(RowBlocks, APassIsTheSameOnAnyNumberOfThreads) {
  const ModelSpec spec = ModelSpec::parse(std::vector<std::string>{"amplitude_imbalance", "quadrature", "harmonics(k3)"});
  Model m(spec, 3, 3);
  m.set("amplitude_imbalance.alpha", 0.1);
  m.set("quadrature.beta", 0.02);
  Design d(spec, m.values(), {});
  d.add_candidate(ModelSpec::parse(std::vector<std::string>{"eccentricity"}).terms.front());
  const std::vector<FitRow> rows = rows_of_a_log();
  const PassStatistics one = pass(d, rows, 1), three = pass(d, rows, 3);
  for (std::size_t g = 0; g < 2; ++g) {
    // Bit for bit: the blocks are the same and added in the same order.
    EXPECT_EQ(one.all[g].m(), three.all[g].m());
    EXPECT_EQ(one.all[g].b(), three.all[g].b());
    EXPECT_EQ(one.all[g].yy(), three.all[g].yy());
    EXPECT_EQ(one.fold_a[g].m(), three.fold_a[g].m());
    EXPECT_EQ(one.all[g].n(), three.all[g].n());
  }
  // And the sums of every row added one by one, to rounding (sums of 2e5 terms: 1e-12).
  PassStatistics plain(d.columns());
  AngleBasis basis;
  SignalValues pred;
  RowJacobian jac;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    d.evaluate(rows, i, basis, pred, jac);
    plain.all[0].add(jac.rd, rows[i].y_rd - pred.rd);
  }
  plain.all[0].flush();
  EXPECT_EQ(plain.all[0].n(), one.all[0].n());
  EXPECT_LT((plain.all[0].m() - one.all[0].m()).norm(), 1e-12 * one.all[0].m().norm());
  EXPECT_LT((plain.all[0].b() - one.all[0].b()).norm(), 1e-12 * one.all[0].b().norm());
}

}  // namespace
}  // namespace resolver
