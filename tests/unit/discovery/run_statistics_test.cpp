// Statistics that merge (run_statistics.h, issue 24): runs fitted apart and merged
// from their statistics give the pooled fit of the same runs; the order of the runs
// does not matter; runs of another bench or without a column are refused by name.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "daemon/core/discovery/pool.h"
#include "daemon/core/discovery/run_statistics.h"
#include "tests/unit/discovery/simulated_input.h"

namespace resolver {
namespace {

const DiscoveryOptions kAligned = [] {
  DiscoveryOptions o;
  o.prepare.reference_aligned = true;
  return o;
}();

const ModelParameter& param(const std::vector<ModelParameter>& ps, const std::string& name) {
  for (const ModelParameter& p : ps) {
    if (p.name == name) return p;
  }
  throw std::out_of_range(name);
}

struct TwoRuns {
  DiscoveryInput slow, fast;
  PreparedLog slow_log, fast_log;
};

// Real magnitudes (a 3 % gain error, a 1 % quadrature) at two speeds.
const TwoRuns& runs() {
  static const TwoRuns r = [] {
    TwoRuns t;
    t.slow = simulate({"amplitude_imbalance:alpha=0.03", "quadrature:beta=0.01"}, {{3.0, 200.0, 200.0}});
    t.fast = simulate({"amplitude_imbalance:alpha=0.03", "quadrature:beta=0.01"}, {{2.0, 450.0, 450.0}});
    t.slow_log = prepare_log(t.slow, kAligned.prepare);
    t.fast_log = prepare_log(t.fast, kAligned.prepare);
    return t;
  }();
  return r;
}

// The simulator's R/D converter (omega_n = 3000 rad/s) is part of every model: a
// nonlinear parameter, so the merge of runs linearised apart is tested too.
const std::vector<std::string> kModel{"amplitude_imbalance", "quadrature", "tracking_loop"};

TEST(RunStatistics, MergedRunsGiveThePooledFitOfTheSameRuns) {
  const TwoRuns& r = runs();
  const std::vector<RunStatistics> stats{run_statistics(r.slow_log, kModel, kAligned),
                                         run_statistics(r.fast_log, kModel, kAligned)};
  const MergedFit merged = merge_runs(stats, {"slow", "fast"}, {}, kAligned);
  const std::vector<const DiscoveryInput*> inputs{&r.slow, &r.fast};
  const PooledLogs pooled = prepare_pooled(inputs, {"slow", "fast"}, kAligned.prepare);
  const ModelFit fit = fit_prepared(pooled.pool, kModel, kAligned);
  for (const char* name : {"amplitude_imbalance.alpha", "quadrature.beta", "tracking_loop.omega_n"}) {
    const ModelParameter& m = param(merged.params, name);
    const ModelParameter& p = param(fit.params, name);
    // The same rows and floors: the pooled fit iterates to convergence, the merge takes
    // one pooled step from each run's own solution, so they differ only at second
    // order in the runs' differences: measured 0.012 standard errors on alpha, 0.008
    // on omega_n, 0.0004 on beta; a twentieth is far below any decision the fit makes.
    EXPECT_NEAR(m.value, p.value, 0.05 * p.std_error) << name << " merged " << m.value << " pooled " << p.value
                                                      << " +- " << p.std_error;
    // Formal (merge) against revolution-spread (pooled) standard errors: same order.
    EXPECT_GT(m.std_error, 0.3 * p.std_error) << name;
    EXPECT_LT(m.std_error, 3.0 * p.std_error) << name;
  }
  EXPECT_NEAR(param(merged.params, "amplitude_imbalance.alpha").value, 0.03, 1e-4);
  EXPECT_TRUE(merged.explained);
  for (const Candidate& c : merged.candidates) EXPECT_FALSE(c.proposed) << c.effect << ": proposed although explained";
  EXPECT_EQ(merged.rows, r.slow_log.fitted_rows() + r.fast_log.fitted_rows());
}

TEST(RunStatistics, TheOrderOfTheRunsDoesNotMatter) {
  const TwoRuns& r = runs();
  const RunStatistics a = run_statistics(r.slow_log, kModel, kAligned);
  const RunStatistics b = run_statistics(r.fast_log, kModel, kAligned);
  const MergedFit ab = merge_runs({a, b}, {"a", "b"}, {}, kAligned);
  const MergedFit ba = merge_runs({b, a}, {"b", "a"}, {}, kAligned);
  ASSERT_EQ(ab.params.size(), ba.params.size());
  for (std::size_t i = 0; i < ab.params.size(); ++i) {
    // Sums in another order: equal to rounding (relative 1e-12 of a value ~1e-2).
    EXPECT_NEAR(ab.params[i].value, ba.params[i].value, 1e-12 * std::abs(ab.params[i].value) + 1e-15);
    EXPECT_NEAR(ab.params[i].std_error, ba.params[i].std_error, 1e-9 * ab.params[i].std_error);
  }
}

TEST(RunStatistics, AMissingEffectIsRankedFromTheMergedStatistics) {
  const TwoRuns& r = runs();
  const std::vector<std::string> alpha_only{"amplitude_imbalance", "tracking_loop"};
  const std::vector<RunStatistics> stats{run_statistics(r.slow_log, alpha_only, kAligned),
                                         run_statistics(r.fast_log, alpha_only, kAligned)};
  const MergedFit merged = merge_runs(stats, {"slow", "fast"}, {}, kAligned);
  EXPECT_FALSE(merged.explained);
  ASSERT_FALSE(merged.candidates.empty());
  EXPECT_EQ(merged.candidates.front().effect, "quadrature");
  EXPECT_TRUE(merged.candidates.front().proposed);
  // The merge can also fit the candidate: the same statistics, another model.
  const MergedFit with = merge_runs(stats, {"slow", "fast"}, kModel, kAligned);
  // A candidate's columns are linearised at zero: at a 1 % quadrature the one step
  // leaves second-order terms of beta^2 ~ 1e-4 rad; the value is right to ~1 %.
  EXPECT_NEAR(param(with.params, "quadrature.beta").value, 0.01, 2e-4);
  // explain on statistics refits it as explain does in memory: the statistics made
  // again with it in the model (each run fitted to convergence), merged.
  // (Here its step already reaches the floor, so explain would not refit it; the
  // delay, a nonlinear parameter, would be: candidates_to_refit.)
  MergedFit ranked = merged;
  const std::vector<std::string> refit = candidates_to_refit(ranked, kAligned);
  EXPECT_TRUE(std::find(refit.begin(), refit.end(), "delay") != refit.end());
  const std::vector<RunStatistics> exact{run_statistics(r.slow_log, kModel, kAligned),
                                         run_statistics(r.fast_log, kModel, kAligned)};
  take_exact_refit(ranked, "quadrature", merge_runs(exact, {"slow", "fast"}, kModel, kAligned), kAligned);
  const Candidate& c = ranked.candidates.front();
  EXPECT_EQ(c.effect, "quadrature");
  EXPECT_TRUE(c.reaches_floor);
  EXPECT_TRUE(c.proposed);
  // Converged: the ADC noise's standard error (~5e-7 here), not the step's 2e-4.
  EXPECT_NEAR(param(c.params, "quadrature.beta").value, 0.01, 1e-5);
  EXPECT_EQ(ranked.refitted, std::vector<std::string>{"quadrature"});
  EXPECT_FALSE(c.stepped);
  EXPECT_NE(c.reason.find("(fit: "), std::string::npos) << c.reason;
  for (const std::string& e : candidates_to_refit(ranked, kAligned)) EXPECT_NE(e, "quadrature") << "refitted twice";
}

/// `whole` cut at `cut_s` into two chunks, each a run's statistics of `model`; the second
/// goes on from where the first left the rotor unless `go_on` is false.
std::vector<RunStatistics> two_chunks(const DiscoveryInput& whole, double cut_s, const std::vector<std::string>& model,
                                      const DiscoveryOptions& options, bool go_on = true) {
  std::vector<RunStatistics> out;
  PrepareOptions prepare = options.prepare;
  for (const auto& [t0, t1] : {std::pair{0.0, cut_s}, std::pair{cut_s, 1e9}}) {
    DiscoveryInput part = whole;
    part.samples.clear();
    for (const Sample& x : whole.samples) {
      if (x.t >= t0 && x.t < t1) part.samples.push_back(x);
    }
    const PreparedLog log = prepare_log(part, prepare);
    out.push_back(run_statistics(log, model, options));
    // As add_chunk: the later chunk on the first one's amplitude and clock, going on from
    // where the first left the rotor.
    prepare.amplitude = log.amplitude;
    prepare.time_origin = log.time_origin;
    if (go_on) prepare.continuation = log.continuation;
  }
  return out;
}

// Chunks of one log (--chunk) are runs of their own; merged here each with its own constants (a
// chunk's sin/cos are normalised by its own amplitude when prepared): merged, they give
// the whole log's fit. Here a reference zero of 2.5 rad (not aligned: fitted), chunked
// in the middle of a ramp from 200 to 450 r/min (a ramp, not a step: a step kicks the
// loop into a transient the steady-state model does not hold).
TEST(RunStatistics, ChunksOfOneLogMergedGiveTheWholeLogsFit) {
  DiscoveryInput whole = simulate({"amplitude_imbalance:alpha=0.03", "quadrature:beta=0.01"},
                                  {{2.0, 200.0, 200.0}, {1.0, 200.0, 450.0}, {2.0, 450.0, 450.0}});
  for (Sample& x : whole.samples) x.theta_m_ref = std::fmod(x.theta_m_ref + 2.5, kTwoPi);
  const DiscoveryOptions options;  // the reference's zero is fitted
  const std::vector<RunStatistics> chunks = two_chunks(whole, 2.5, kModel, options);
  const MergedFit merged = merge_runs(chunks, {"log [0-2.5 s]", "log [2.5-5 s]"}, {}, options);
  const ModelFit fit = fit_prepared(prepare_log(whole, options.prepare), kModel, options);
  for (const char* name : {"amplitude_imbalance.alpha", "quadrature.beta", "tracking_loop.omega_n"}) {
    const ModelParameter& m = param(merged.params, name);
    const ModelParameter& p = param(fit.params, name);
    // One step from the chunks' own solutions against the whole log iterated: second
    // order in how far the chunks' fits lie apart. Measured 0.0001, 0.013 and 0.003
    // standard errors; sharing the constants instead was 0.2 se off (the chunks'
    // amplitude normalisations differ).
    EXPECT_NEAR(m.value, p.value, 0.05 * p.std_error) << name << " merged " << m.value << " whole " << p.value
                                                      << " +- " << p.std_error;
  }
  EXPECT_TRUE(merged.explained);
  EXPECT_EQ(merged.rows, chunks[0].fitted_rows + chunks[1].fitted_rows);
}

// The chunks of one log share its reference zero (merge_runs' log_of), as the log's fit
// in memory has one. An out-and-back cut in the standstill at the reversal, a play of 4
// mrad, the reference's zero at 2.5 rad (fitted): with a zero of its own each chunk takes
// the play as its constant (+-h/2) and the merge cannot see it; with the log's zero shared
// the merge names backlash, fitted from the chunks (refit_from_logs). The second chunk
// goes on from where the first left the rotor (PrepareOptions::continuation): it knows
// the play was taken up forward, so its first motion is a reversal with its take-up.
TEST(RunStatistics, ChunksOfOneLogShareItsReferenceZero) {
  DiscoveryInput whole = simulate({"amplitude_imbalance:alpha=0.003", "backlash:h=0.004"},
                                  {{2.0, 150.0, 150.0}, {0.5, 0.0, 0.0}, {2.0, -150.0, -150.0}});
  for (Sample& x : whole.samples) x.theta_m_ref = std::fmod(x.theta_m_ref + 2.5, kTwoPi);
  const DiscoveryOptions options;  // the reference's zero is fitted
  const std::vector<std::string> model{"amplitude_imbalance"};
  const std::vector<std::string> names{"log [0-2.25 s]", "log [2.25-4.5 s]"};
  const auto named = [](const MergedFit& m) {
    return std::any_of(m.candidates.begin(), m.candidates.end(), [](const Candidate& c) { return c.effect == "backlash"; });
  };
  const MergedFit apart = merge_runs(two_chunks(whole, 2.25, model, options, false), names, {}, options);
  EXPECT_FALSE(named(apart)) << "each chunk's own zero takes the play: nothing left to see";
  const std::vector<int> one_log{0, 0};
  const MergedFit shared = merge_runs(two_chunks(whole, 2.25, model, options), names, {}, options, one_log);
  // Proposed (beside delay: at one speed each way a delay is the same offset until refitted).
  const auto backlash = std::find_if(shared.candidates.begin(), shared.candidates.end(),
                                     [](const Candidate& c) { return c.effect == "backlash"; });
  ASSERT_NE(backlash, shared.candidates.end());
  EXPECT_TRUE(backlash->proposed);
  // One zero, shown under both chunks' names.
  EXPECT_DOUBLE_EQ(param(shared.nuisance, "nuisance.rd_constant[log [0-2.25 s]]").value,
                   param(shared.nuisance, "nuisance.rd_constant[log [2.25-4.5 s]]").value);
  // The first chunk turns one way: its rows alone cannot separate the play from its zero,
  // and it holds the play at the merged value; the second reverses and fits it.
  DiscoveryOptions held = options;
  held.start.values = backlash->params;
  held.start.held = {"backlash"};
  held.statistics_candidates = false;  // as refit_from_logs: the model's columns only
  const std::vector<std::string> with{"amplitude_imbalance", "backlash"};
  const std::vector<RunStatistics> again = two_chunks(whole, 2.25, with, held);
  EXPECT_EQ(again[0].held, std::vector<std::string>{"backlash"});
  EXPECT_TRUE(again[1].held.empty());
  const MergedFit exact = merge_runs(again, names, with, options, one_log);
  EXPECT_EQ(exact.held, std::vector<std::string>{"backlash"});  // the report says it was stepped, not fitted per run
  const ModelFit fit = fit_prepared(prepare_log(whole, options.prepare), with, options);
  const ModelParameter& m = param(exact.params, "backlash.h");
  const ModelParameter& p = param(fit.params, "backlash.h");
  // The same rows with the same take-up as the whole log: measured 8e-5 standard errors.
  EXPECT_NEAR(m.value, p.value, 0.05 * p.std_error) << "merged " << m.value << " whole " << p.value << " +- " << p.std_error;
  // The control: a second chunk that starts afresh takes the play as taken up in the
  // direction of its first motion, and its take-up rows are mismatched: measured 20 se.
  const MergedFit afresh = merge_runs(two_chunks(whole, 2.25, with, held, false), names, with, options, one_log);
  EXPECT_GT(std::abs(param(afresh.params, "backlash.h").value - p.value), 1.0 * p.std_error);
}

// The chunks of one log share its envelopes' gain and clock too (add_chunk: a later chunk
// is normalised by the first one's amplitude, its t counted from the first one's origin),
// as the log's fit in memory has one gain and one time axis. An excitation drifting by
// 0.1 %/s, cut in the middle: with a gain and a clock per chunk, each chunk's gain takes
// the drift's level at its start, and only the slope within each chunk is left to it.
TEST(RunStatistics, ChunksOfOneLogShareItsGainAndClock) {
  const DiscoveryInput whole = simulate({"amplitude_imbalance:alpha=0.003", "envelope_drift:g=0.001"},
                                        {{4.0, 200.0, 200.0}});
  const DiscoveryOptions options;
  const std::vector<std::string> model{"amplitude_imbalance", "envelope_drift"};
  const std::vector<RunStatistics> chunks = two_chunks(whole, 2.0, model, options);
  const std::vector<std::string> names{"log [0-2 s]", "log [2-4 s]"};
  const MergedFit shared = merge_runs(chunks, names, model, options, std::vector<int>{0, 0});
  const ModelFit fit = fit_prepared(prepare_log(whole, options.prepare), model, options);
  const ModelParameter& m = param(shared.params, "envelope_drift.g");
  const ModelParameter& p = param(fit.params, "envelope_drift.g");
  // Measured 0.009 standard errors (the chunks' own floors weigh their rows); apart, 2.3.
  EXPECT_NEAR(m.value, p.value, 0.05 * p.std_error) << "merged " << m.value << " whole " << p.value;
  // Apart, the level of the drift between the chunks is lost to their gains: measured a
  // standard error 2.0x the shared one's.
  const MergedFit apart = merge_runs(chunks, names, model, options);
  EXPECT_GT(param(apart.params, "envelope_drift.g").std_error, 1.5 * m.std_error);
  EXPECT_DOUBLE_EQ(param(shared.nuisance, "nuisance.sincos_gain[log [0-2 s]]").value,
                   param(shared.nuisance, "nuisance.sincos_gain[log [2-4 s]]").value);
}

// A nonlinear model's merge moves each chunk's statistics linearly from the chunk's own fit
// to the merged point: exact to second order in how far those lie apart. A mounting offset
// of 50 mrad the model lacks turns the dq currents (the hidden-effect matrix's
// mounting_offset case, its reversals profile), so the chunks' own fits of the gain error
// differ, and the candidate's columns, taken at each chunk's own point, rank it from the
// wrong place. Statistics made again at the merged fit (FitStartValues::at_start:
// Gauss-Newton over passes, stats_run.h relinearise_merge) give the whole log's fit.
TEST(RunStatistics, ChunksMadeAgainAtTheMergedFitGiveTheWholeLogsNonlinearFit) {
  const DiscoveryInput whole =
      simulate({"amplitude_imbalance:alpha=0.003", "mounting_offset:theta_0=0.05"},
               {{1.0, 120.0, 120.0}, {0.5, 120.0, -120.0}, {1.0, -120.0, -120.0}, {0.5, -120.0, 120.0},
                {1.0, 120.0, 120.0}, {0.5, 60.0, 60.0}, {0.5, -60.0, -60.0}});
  const DiscoveryOptions options = kAligned;  // a mounting offset is seen against an aligned reference
  const std::vector<std::string> model{"amplitude_imbalance"};
  const std::vector<std::string> names{"log [0-2.5 s]", "log [2.5-5 s]"};
  const std::vector<int> one_log{0, 0};
  const MergedFit once = merge_runs(two_chunks(whole, 2.5, model, options), names, model, options, one_log);
  ASSERT_TRUE(once.nonlinear);
  // How far that merge lies from the chunks' own fits, in the signals: measured 154 floors
  // per row (Gauss-Newton over passes is asked for from delta^2 sqrt(N) >= 0.05: stats_run.cpp).
  EXPECT_GT(once.run_move, 10.0);
  MergedFit merged = once;
  DiscoveryOptions again = options;
  again.start.settled = model;
  again.start.at_start = true;
  for (int pass = 0; pass < 2; ++pass) {
    again.start.values = merged.params;
    const std::vector<RunStatistics> at = two_chunks(whole, 2.5, model, again);
    for (const RunStatistics& r : at) EXPECT_TRUE(r.at_merged);
    merged = merge_runs(at, names, model, again, one_log);
  }
  const auto offset_of = [](const MergedFit& m) {
    for (const Candidate& c : m.candidates) {
      if (c.effect == "mounting_offset") return param(c.params, "mounting_offset.theta_0");
    }
    throw std::out_of_range("mounting_offset not ranked");
  };
  const PreparedLog log = prepare_log(whole, options.prepare);
  const ModelParameter a = param(fit_prepared(log, model, options).params, "amplitude_imbalance.alpha");
  const ModelParameter w =
      param(fit_prepared(log, std::vector<std::string>{"amplitude_imbalance", "mounting_offset"}, options).params,
            "mounting_offset.theta_0");
  // Made again at the merged fit the chunks' statistics are the whole log's at that point
  // (the same rows; what differs is the chunks' own floors): measured 0.014 standard
  // errors on the candidate (its step is its fit: the offset is linear), 1e-5 on alpha.
  EXPECT_NEAR(offset_of(merged).value, w.value, 0.05 * w.std_error)
      << "relinearised " << offset_of(merged).value << " whole " << w.value << " +- " << w.std_error;
  EXPECT_NEAR(param(merged.params, "amplitude_imbalance.alpha").value, a.value, 0.05 * a.std_error);
  // The control: from each chunk's own point the candidate was measured 1.6 se off.
  EXPECT_GT(std::abs(offset_of(once).value - w.value), 0.5 * w.std_error) << "the one step is already the fit";
}

TEST(RunStatistics, RunsOfAnotherBenchOrWithoutAColumnAreRefusedByName) {
  const TwoRuns& r = runs();
  RunStatistics a = run_statistics(r.slow_log, kModel, kAligned);
  RunStatistics b = a;
  b.layout.p_r = 2;
  try {
    (void)merge_runs({a, b}, {"a.stats", "b.stats"}, {}, kAligned);
    FAIL() << "merged runs of two benches";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("b.stats: pole pairs"), std::string::npos) << e.what();
  }
  // A run whose statistics lack a column the model needs (made by a catalog without it).
  RunStatistics c = a;
  for (std::string& name : c.columns) {
    if (name == "quadrature.beta") name = "quadrature.renamed";
  }
  try {
    (void)merge_runs({a, c}, {"a.stats", "c.stats"}, kModel, kAligned);
    FAIL() << "fitted a column c.stats lacks";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("c.stats has no column quadrature.beta"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace resolver
