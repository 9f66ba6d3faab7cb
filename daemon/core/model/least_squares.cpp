#include "daemon/core/model/least_squares.h"

#include <cmath>
#include <limits>
#include <numeric>

#include "daemon/core/model/row_blocks.h"

namespace resolver {

namespace {
/// Smallest eigenvalue of the unit-diagonal normal matrix a fit accepts: for two
/// columns it is 1 - |correlation|; 1e-5 is a correlation of 0.99999.
constexpr double kCollinear = 1e-5;
}  // namespace

PassStatistics::PassStatistics(int columns) {
  for (int g = 0; g < kGroups; ++g) {
    all.emplace_back(columns);
    fold_a.emplace_back(columns);
  }
}

void PassStatistics::merge(const PassStatistics& other) {
  for (int g = 0; g < kGroups; ++g) {
    all[static_cast<std::size_t>(g)].merge(other.all[static_cast<std::size_t>(g)]);
    fold_a[static_cast<std::size_t>(g)].merge(other.fold_a[static_cast<std::size_t>(g)]);
  }
}

NormalEquations PassStatistics::fold_b(Group g) const {
  const auto i = static_cast<std::size_t>(g);
  NormalEquations out;
  out.set(all[i].m() - fold_a[i].m(), all[i].b() - fold_a[i].b(), all[i].yy() - fold_a[i].yy(),
          all[i].n() - fold_a[i].n());
  return out;
}

namespace {

/// Rows [from, to) of one pass added to `out` (unflushed).
void accumulate_rows(const Design& design, std::span<const FitRow> rows, std::size_t from, std::size_t to,
                     const GroupFloors& floors, PassStatistics& out) {
  AngleBasis basis;
  SignalValues pred;
  RowJacobian jac;
  jac.resize(design.columns());
  const bool use_rd = floors.rd > 0.0, use_sc = floors.sc > 0.0, use_cur = floors.cur > 0.0;
  for (std::size_t i = from; i < to; ++i) {
    const FitRow& r = rows[i];
    if (!r.fitted()) continue;
    design.evaluate(rows, i, basis, pred, jac);
    const bool b = r.has(FitRow::kFoldB);
    auto add = [&](Group g, const Eigen::VectorXd& x, double y) {
      const auto k = static_cast<std::size_t>(g);
      out.all[k].add(x, y);
      if (!b) out.fold_a[k].add(x, y);
    };
    if (use_rd && r.has(FitRow::kHasRd)) add(Group::kRd, jac.rd, r.y_rd - pred.rd);
    if (use_sc && r.has(FitRow::kHasSc)) {
      add(Group::kSc, jac.sa, r.y_sa - pred.sa);
      add(Group::kSc, jac.sr, r.y_sr - pred.sr);
    }
    if (use_cur && r.has(FitRow::kHasCur)) {
      add(Group::kCur, jac.d, r.y_d - pred.d);
      add(Group::kCur, jac.q, r.y_q - pred.q);
    }
  }
}

void flush(PassStatistics& s) {
  for (auto& g : s.all) g.flush();
  for (auto& g : s.fold_a) g.flush();
}

}  // namespace

void accumulate(const Design& design, std::span<const FitRow> rows, const GroupFloors& floors, PassStatistics& out) {
  if (out.all.empty() || out.all.front().columns() != design.columns()) out = PassStatistics(design.columns());
  if (rows.size() <= kRowBlock) {
    accumulate_rows(design, rows, 0, rows.size(), floors, out);
  } else {
    // Blocks summed apart and added in order (row_blocks.h): the same sums on any number
    // of threads. A design's evaluation keeps scratch in it: one copy per further worker.
    const int workers = row_block_workers(rows.size());
    std::vector<Design> copies(static_cast<std::size_t>(workers - 1), design);
    std::vector<PassStatistics> parts(static_cast<std::size_t>(workers), PassStatistics(design.columns()));
    over_row_blocks(
        rows.size(), workers,
        [&](int w, std::size_t from, std::size_t to) {
          const Design& d = w == 0 ? design : copies[static_cast<std::size_t>(w - 1)];
          accumulate_rows(d, rows, from, to, floors, parts[static_cast<std::size_t>(w)]);
        },
        [&](int w) {
          PassStatistics& part = parts[static_cast<std::size_t>(w)];
          flush(part);
          out.merge(part);
          part = PassStatistics(design.columns());
        });
  }
  flush(out);
}

StepSolution solve_step(const std::vector<NormalEquations>& groups, const GroupFloors& floors,
                        std::span<const int> columns, double lambda) {
  StepSolution out;
  const int full = groups.front().columns();
  std::vector<int> cols(columns.begin(), columns.end());
  if (cols.empty()) {
    for (int j = 0; j < full; ++j) cols.push_back(j);
  }
  const auto k = static_cast<Eigen::Index>(cols.size());
  Eigen::MatrixXd m = Eigen::MatrixXd::Zero(k, k);
  Eigen::VectorXd b = Eigen::VectorXd::Zero(k);
  double yy_w = 0.0;
  for (int g = 0; g < kGroups; ++g) {
    const double f = floors.of(static_cast<Group>(g));
    const NormalEquations& ne = groups[static_cast<std::size_t>(g)];
    if (!(f > 0.0) || ne.n() == 0) continue;
    const double w = 1.0 / (f * f);
    for (Eigen::Index a = 0; a < k; ++a) {
      b[a] += w * ne.b()[cols[static_cast<std::size_t>(a)]];
      for (Eigen::Index c = 0; c < k; ++c) {
        m(a, c) += w * ne.m()(cols[static_cast<std::size_t>(a)], cols[static_cast<std::size_t>(c)]);
      }
    }
    yy_w += w * ne.yy();
  }
  out.dz = Eigen::VectorXd::Zero(full);
  out.inverse = Eigen::MatrixXd::Zero(full, full);
  out.k = static_cast<int>(k);
  Eigen::VectorXd step = Eigen::VectorXd::Zero(k);
  if (k > 0) {
    // Scale to unit diagonal so the rank test is about collinearity, not units.
    const Eigen::VectorXd dg = m.diagonal().cwiseMax(1e-300).cwiseSqrt();
    const Eigen::VectorXd inv = dg.cwiseInverse();
    Eigen::MatrixXd ms = inv.asDiagonal() * m * inv.asDiagonal();
    Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> cod(ms);
    cod.setThreshold(1e-9);
    if (cod.rank() < k) return out;
    // Nearly collinear columns (a column explained to 1 - 1e-5 by the others: e.g.
    // alpha's 2 theta and a mechanical order 2 at p_r = 1 without sin/cos, apart from
    // alpha's own 1e-3 series terms) would give a fit the data does not support.
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(ms, Eigen::EigenvaluesOnly);
    if (eig.eigenvalues().minCoeff() < kCollinear) return out;
    if (lambda > 0.0) ms.diagonal().array() += lambda;
    const Eigen::MatrixXd ms_inv = ms.inverse();
    step = inv.asDiagonal() * (ms_inv * (inv.asDiagonal() * b));
    const Eigen::MatrixXd minv = inv.asDiagonal() * cod.pseudoInverse() * inv.asDiagonal();
    for (Eigen::Index a = 0; a < k; ++a) {
      out.dz[cols[static_cast<std::size_t>(a)]] = step[a];
      for (Eigen::Index c = 0; c < k; ++c) {
        out.inverse(cols[static_cast<std::size_t>(a)], cols[static_cast<std::size_t>(c)]) = minv(a, c);
      }
    }
  }
  // Per-group RSS after the step, from the statistics (linearised).
  out.rss_w = 0.0;
  for (int g = 0; g < kGroups; ++g) {
    const NormalEquations& ne = groups[static_cast<std::size_t>(g)];
    out.n[g] = ne.n();
    if (ne.n() == 0) continue;
    out.rss[g] = ne.rss(out.dz);
    const double f = floors.of(static_cast<Group>(g));
    if (f > 0.0) out.rss_w += out.rss[g] / (f * f);
  }
  out.ok = true;
  (void)yy_w;
  return out;
}

namespace {

/// The cost at the statistics' point: the weighted RSS with the nuisance constants
/// solved there (they are not stored between passes). Without them the cost would
/// carry the operating point (i_q of 10 A against a floor of 0.02 A), and a step
/// that moves a parameter's constant part would read as worse while it is better.
double cost_at(const PassStatistics& s, const GroupFloors& floors, std::span<const int> nuisance_cols) {
  if (!nuisance_cols.empty()) {
    const StepSolution n = solve_step(s.all, floors, std::vector<int>(nuisance_cols.begin(), nuisance_cols.end()));
    if (n.ok) return n.rss_w;
  }
  return weighted_yy(s.all, floors);
}

/// [rad] a change of the frame shift that no longer matters: it turns a harmonic error
/// of 0.1 rad by 1e-8 rad, far below any floor (a 24-bit converter's LSB is 3.7e-7).
constexpr double kShiftSettled = 1e-7;
/// Levenberg-Marquardt damping on the scaled normal equations' unit diagonal: the first
/// after an uphill step, and the last tried before the last good point is the answer.
constexpr double kFirstDamping = 1.0;
constexpr double kLastDamping = 100.0;
/// The largest undamped step left at a fit's end, in standard errors, for the fit to be
/// converged: a tenth of one standard error's cost (sqrt(0.1)).
const double kNegligibleStepSe = std::sqrt(0.1);

/// The columns of the position-error constant the frame shift follows, one per
/// pooled part (design.h): the sin/cos angle's where the log has it (the windings'
/// own frame), else the R/D angle's; empty when the reference is aligned (no
/// constant: mounting_offset is a parameter).
std::vector<int> frame_constant_columns(const Design& d) {
  int kind = -1;
  for (std::size_t j = 0; j < d.nuisances().size(); ++j) {
    if (d.nuisances()[j] == Nuisance::kSaConstant) {
      kind = static_cast<int>(j);
      break;
    }
    if (d.nuisances()[j] == Nuisance::kRdConstant) kind = static_cast<int>(j);
  }
  std::vector<int> out;
  if (kind < 0) return out;
  for (int part = 0; part < d.parts(); ++part) out.push_back(d.nuisance_column(part, static_cast<std::size_t>(kind)));
  return out;
}

/// Every part's frame shift moved by its constant's step (the prediction carries
/// -shift: design.h).
void shift_frames(Design& d, const std::vector<int>& zero_cols, const Eigen::VectorXd& dz) {
  for (std::size_t part = 0; part < zero_cols.size(); ++part) {
    d.set_frame_shift(static_cast<int>(part), d.frame_shift(static_cast<int>(part)) - dz[zero_cols[part]]);
  }
}

/// True when design column `col` is a model term's nonlinear parameter.
bool column_is_nonlinear(const Design& d, int col) {
  for (std::size_t i = 0; i < d.terms().size(); ++i) {
    const DesignTerm& t = d.terms()[i];
    const int first = d.term_column(i);
    if (col < first || col >= first + static_cast<int>(t.params.size())) continue;
    return t.effect->params()[static_cast<std::size_t>(t.params[static_cast<std::size_t>(col - first)])].nonlinear;
  }
  return false;
}

}  // namespace

double weighted_yy(const std::vector<NormalEquations>& groups, const GroupFloors& floors) {
  double c = 0.0;
  for (int g = 0; g < kGroups; ++g) {
    const double f = floors.of(static_cast<Group>(g));
    if (f > 0.0) c += groups[static_cast<std::size_t>(g)].yy() / (f * f);
  }
  return c;
}

bool strictly_linear(const Design& d) {
  for (const DesignTerm& t : d.terms()) {
    if (t.candidate) continue;
    if (!t.effect->linear_in_params()) return false;
  }
  return !d.nonlinear();
}

int fit_frame_shift(Design& design, std::span<const FitRow> rows, const GroupFloors& floors, int max_passes) {
  const std::vector<int> zero_cols = frame_constant_columns(design);
  // Every nuisance column with it: the R/D angle's constant (the converter's own zero)
  // and the envelopes' gain are solved beside the shift, not left in it.
  std::vector<int> nuisance_cols(static_cast<std::size_t>(design.nuisance_columns()));
  std::iota(nuisance_cols.begin(), nuisance_cols.end(), 0);
  int passes = 0;
  while (!zero_cols.empty() && passes < max_passes) {
    PassStatistics stats(design.columns());
    accumulate(design, rows, floors, stats);
    ++passes;
    const StepSolution c = solve_step(stats.all, floors, nuisance_cols);
    if (!c.ok) break;
    shift_frames(design, zero_cols, c.dz);
    bool settled = true;
    for (int col : zero_cols) settled = settled && std::abs(c.dz[col]) <= kShiftSettled;
    if (settled) break;
  }
  return passes;
}

namespace {

/// A fit that stopped where its damped steps went uphill is converged only where the
/// undamped step left is too small to matter (step_in_standard_errors below 0.3, a tenth of
/// a standard error's cost); with a larger step left it stopped on a slope (a candidate
/// nearly an alias of model terms stayed at its start, reported as its fit).
bool step_negligible(const StepSolution& s, double cost) { return step_in_standard_errors(s, cost) <= kNegligibleStepSe; }

FitResult fit_from_start(Design& design, std::span<const FitRow> rows, const GroupFloors& floors, int max_passes,
                         const std::function<void()>& progress, bool settled_start) {
  FitResult out;
  // Model columns only: candidates are evaluated at the model's solution later.
  std::vector<int> model_cols;
  model_cols.reserve(static_cast<std::size_t>(design.columns()));
  for (int j = 0; j < design.nuisance_columns(); ++j) model_cols.push_back(j);
  const std::vector<int> nuisance_cols = model_cols;
  for (std::size_t i = 0; i < design.terms().size(); ++i) {
    if (design.terms()[i].candidate) continue;
    for (std::size_t k = 0; k < design.terms()[i].params.size(); ++k) {
      model_cols.push_back(design.term_column(i) + static_cast<int>(k));
    }
  }
  const bool linear = strictly_linear(design);
  // The first step holds the nonlinear parameters at their start: they act through
  // the other effects' harmonics (a loop filters them, a delay turns them), whose
  // columns are all zero at the neutral start, so a joint first step is a guess in
  // an ill-conditioned direction (a loop once jumped to omega_n = 13 rad/s, filtered
  // everything and stayed on that plateau at 364x the floor).
  // From a settled start (every model term at a converged fit: a live window started
  // where the last one ended) those columns are not zero and the joint step is the
  // right one: holding the nonlinear parameters would only cost a pass.
  std::vector<int> warm_cols;
  for (int c : model_cols) {
    if (settled_start || !column_is_nonlinear(design, c)) warm_cols.push_back(c);
  }
  const std::vector<int> zero_cols = linear ? std::vector<int>{} : frame_constant_columns(design);
  // Start in the sensor's frame: the constant alone at the starting values (its
  // error is the windings' mean angle error, ~beta/2). From a frame half a turn
  // away the first step would fit every harmonic turned and could only go uphill.
  // (A settled start still takes this pass: started at the last window's shift, a fit
  // under a model far from the floor kept that point, whose cost was lower than where the
  // constant's steps converge, and ended 0.75 standard errors from the cold fit.)
  if (!zero_cols.empty()) out.passes += fit_frame_shift(design, rows, floors, 1);
  double lambda = 0.0;
  double cost = std::numeric_limits<double>::infinity();
  Design last_good = design;
  PassStatistics good_stats(design.columns());  // at last_good: a step back costs no pass
  bool back = false;
  bool stepped = false;  // design is a step from last_good, not yet taken as good
  double last_step_se = std::numeric_limits<double>::infinity();  // that step's move, undamped
  for (int pass = 0; pass < max_passes; ++pass) {
    PassStatistics stats(design.columns());
    if (back) {
      stats = good_stats;
    } else {
      accumulate(design, rows, floors, stats);
      ++out.passes;
      if (progress) progress();
    }
    const double here = back ? cost : cost_at(stats, floors, nuisance_cols);
    // Rounding in sums over many rows moves the cost by ~1e-12 relative: a rise
    // smaller than the convergence tolerance is not a worse step.
    const double tolerance = 1e-9 * here + 1e-6;
    if (!back && here > cost + tolerance) {
      // The last step made it worse (nonlinear): go back and damp. When the damped
      // steps go uphill too, the last good point is the answer, never an uphill one
      // (a tracking loop once ended at omega_n = 14 rad/s, 364x the floor, from an
      // ideal converter at 1x). The damping is added to the unit diagonal of the scaled
      // normal equations: the first damped step takes 1 (about half the step where the
      // columns are well apart, far less along nearly collinear ones), the second 100;
      // then it ends (a refit near its solution once spent 10 of its 12 passes on damped
      // steps and ended at the last good point all the same). It took 1e-4 first, which
      // is no damping: the same step again, uphill, and the fit ended at its start (a
      // slow loop's omega_n and zeta fitted together stayed at the start values, 247x
      // the floor).
      design = last_good;
      stepped = false;
      // An undamped step worth less than the negligible move (step_negligible) that went
      // uphill all the same is the linearisation's own error at the solution (numeric
      // derivatives, curvature): a damped one could gain less still, so the last good
      // point is the fit (the damping took 3-4 more passes to end there).
      if (lambda >= kLastDamping || (lambda == 0.0 && last_step_se <= kNegligibleStepSe)) {
        out.last = solve_step(good_stats.all, floors, model_cols, 0.0);
        out.stats = std::move(good_stats);
        out.cost = cost;
        out.ok = out.last.ok;
        out.converged = out.ok && step_negligible(out.last, cost);
        return out;
      }
      // Used after the /10 below: 1, then 100.
      lambda = lambda < kFirstDamping ? 10.0 * kFirstDamping : lambda * 1000.0;
      back = true;
      continue;
    }
    back = false;
    lambda = lambda / 10.0 < 1e-9 ? 0.0 : lambda / 10.0;
    std::vector<int> cols = pass == 0 ? warm_cols : model_cols;
    StepSolution sol = solve_step(stats.all, floors, cols, lambda);
    // Parameters at a bound that the step pushes past are held there (their solution
    // is the bound: an ideal converter, no play), and the rest solved without them.
    if (sol.ok && std::erase_if(cols, [&](int c) { return design.pushed_past_bound(c, sol.dz[c]); }) > 0) {
      sol = solve_step(stats.all, floors, cols, lambda);
    }
    if (!sol.ok && stepped) {
      // The last step landed where the columns cannot be solved: a lightly damped loop's
      // zeta stepped from 0.7 to its bound 0.01 in one go (where zeta and omega_n no longer
      // separate), and every start ended "not separable". Back to the point it left (still
      // last_good, with its statistics and cost), damped like an uphill step.
      design = last_good;
      lambda = lambda < kFirstDamping ? 10.0 * kFirstDamping : lambda * 1000.0;
      back = true;
      stepped = false;
      continue;
    }
    cost = here;
    last_good = design;
    good_stats = stats;
    if (!sol.ok) {
      out.last = sol;
      out.stats = std::move(stats);
      return out;
    }
    // Converged when the step lowers the cost by a negligible amount (1e-9 relative
    // or less than 1e-6 of one row's noise): the statistics are at the solution.
    // Judged on the undamped step: a damped one is small because of the damping
    // (and damps the nuisance constants the report takes from it), not because the
    // point is the solution.
    // The frame shift is the position-error constant's coordinate (the prediction
    // carries -shift: design.h); the constant's step moves it like any parameter.
    bool shift_settled = true;
    for (int c : zero_cols) shift_settled = shift_settled && std::abs(sol.dz[c]) <= kShiftSettled;
    if (pass > 0 && shift_settled && here - sol.rss_w <= tolerance) {
      const StepSolution free = lambda > 0.0 ? solve_step(stats.all, floors, cols, 0.0) : sol;
      if (free.ok && here - free.rss_w <= tolerance) {
        out.last = free;
        out.stats = std::move(stats);
        out.cost = here;
        out.ok = true;
        out.converged = true;
        return out;
      }
    }
    out.last = sol;
    last_step_se = step_in_standard_errors(sol, here);
    out.stats = std::move(stats);
    design.step(sol.dz);
    stepped = true;
    shift_frames(design, zero_cols, sol.dz);
    if (linear) {
      // One linearised step is exact; the statistics move with it (RSS(dz) above).
      out.cost = sol.rss_w;
      out.ok = true;
      out.converged = true;
      return out;
    }
  }
  // Out of passes: the last step was never evaluated. Keep it only if it is not
  // worse than the last point that was; the statistics and solution are the kept point's.
  PassStatistics final_stats(design.columns());
  accumulate(design, rows, floors, final_stats);
  ++out.passes;
  double final_cost = cost_at(final_stats, floors, nuisance_cols);
  if (final_cost > cost + 1e-9 * cost + 1e-6) {
    design = last_good;
    final_stats = PassStatistics(design.columns());
    accumulate(design, rows, floors, final_stats);
    ++out.passes;
    final_cost = cost;
  }
  out.last = solve_step(final_stats.all, floors, model_cols, 0.0);
  out.stats = std::move(final_stats);
  out.cost = final_cost;
  out.ok = out.last.ok;
  out.converged = out.ok && step_negligible(out.last, final_cost);
  return out;
}

/// Other starting values of a model's nonlinear parameter, where its cost has more
/// than one valley (the loop's |H| and the delay's phase wrap; the take-up of a play):
/// a tracking loop at 30000, 10000, 3000, 1000 and 300 rad/s (z = 1 / omega_n^2: a slow loop
/// of 800 rad/s whose resonance the ripple crosses ended at 286 rad/s, 738x its floor, from
/// the ladder without 1000), other parameters
/// a thousandth of their range either side of the start.
std::vector<double> other_starts(const ParamInfo& p, double start) {
  if (p.scale == FitScale::kInverseSquare) return {3e4, 1e4, 3e3, 1e3, 3e2};
  const double step = 1e-3 * (p.max - p.min);
  std::vector<double> out;
  for (double v : {start + step, start - step}) {
    if (v >= p.min && v <= p.max) out.push_back(v);
  }
  return out;
}

}  // namespace

double step_in_standard_errors(const StepSolution& s, double cost) {
  // Each row weighs 1 at its floor, so a move of one standard error lowers the cost by
  // max(1, cost / rows) (the standard errors scale with the residual); the step lowers
  // it by cost - rss_w, a move of sqrt of their ratio.
  const auto rows = static_cast<double>(s.n[0] + s.n[1] + s.n[2]);
  const double per_standard_error = rows > 0.0 ? std::max(1.0, cost / rows) : 1.0;
  return std::sqrt(std::max(0.0, cost - s.rss_w) / per_standard_error);
}

FitResult fit_design(Design& design, std::span<const FitRow> rows, const GroupFloors& floors, int max_passes,
                     const std::function<void()>& progress, const std::vector<bool>& settled) {
  const Design start = design;
  bool settled_start = !settled.empty();
  for (std::size_t i = 0; i < start.terms().size(); ++i) {
    if (!start.terms()[i].candidate) settled_start = settled_start && i < settled.size() && settled[i];
  }
  FitResult best = fit_from_start(design, rows, floors, max_passes, progress, settled_start);
  // Several starts for the parameters whose cost is multimodal: keep the lowest cost
  // among the fits that ended (issue 21: a single start diverged into a far valley).
  for (std::size_t i = 0; i < start.terms().size(); ++i) {
    const DesignTerm& t = start.terms()[i];
    if (t.candidate || (i < settled.size() && settled[i])) continue;
    for (int p : t.params) {
      const ParamInfo& info = t.effect->params()[static_cast<std::size_t>(p)];
      if (!info.nonlinear || info.polar != Polar::kNone) continue;
      for (double v : other_starts(info, t.values[static_cast<std::size_t>(p)])) {
        Design trial = start;
        trial.terms()[i].values[static_cast<std::size_t>(p)] = v;
        FitResult r = fit_from_start(trial, rows, floors, max_passes, progress, false);
        r.passes += best.passes;
        if (r.ok && (!best.ok || r.cost < best.cost)) {
          best = std::move(r);
          design = trial;
        } else {
          best.passes = r.passes;
        }
      }
    }
  }
  return best;
}

}  // namespace resolver
