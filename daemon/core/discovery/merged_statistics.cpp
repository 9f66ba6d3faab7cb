#include "daemon/core/discovery/merged_statistics.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

#include <Eigen/Dense>

#include "daemon/core/discovery/fit_support.h"

namespace resolver {

int column_index(const std::vector<std::string>& names, const std::string& name) {
  const auto it = std::find(names.begin(), names.end(), name);
  return it == names.end() ? -1 : static_cast<int>(it - names.begin());
}

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// The reference zero's constants (the position errors'), which a run holds in its
/// own fit's frame (frame_shift) rather than at zero.
bool frame_constant(const std::string& column) {
  return column == nuisance_name(Nuisance::kRdConstant) || column == nuisance_name(Nuisance::kSaConstant);
}

/// The chunks of one log share its reference zero (one constant per position error: the
/// R/D's, the sin/cos angle's) and its envelopes' gain (the chunks are normalised by one
/// amplitude, PrepareOptions::amplitude; a gain per chunk would take a drift of the
/// envelopes over time as steps between chunks). They are held after the design's
/// columns while the log's runs are added, then profiled out (profile_shared).
constexpr int kSharedConstants = 3;

int shared_slot(const std::string& column) {
  if (column == nuisance_name(Nuisance::kRdConstant)) return 0;
  if (column == nuisance_name(Nuisance::kSaConstant)) return 1;
  if (column == nuisance_name(Nuisance::kScGain)) return 2;
  return -1;
}

/// Where a run's columns go in the merged design and how far each is moved: its own
/// constants (the first columns) are profiled out, the design's columns kept, the rest
/// held at their neutral value. With `share` its reference zero and gain go to the log's
/// shared columns instead, the zero moved by the run's frame shift: the run holds it at
/// zero in its own fit's frame, the log's is in the log's frame (constants_at).
struct RunColumns {
  std::vector<int> to;    ///< run column -> design column, -1: a constant or held
  Eigen::VectorXd shift;  ///< z_r - target (0 for the constants)
};

RunColumns run_columns(const RunStatistics& run, const Design& d, const Eigen::VectorXd& z0, bool share) {
  const std::vector<std::string> names = d.column_names();
  RunColumns rc{std::vector<int>(run.columns.size(), -1), run.point};
  for (std::size_t c = 0; c < run.columns.size(); ++c) {
    const auto i = static_cast<Eigen::Index>(c);
    if (static_cast<int>(c) < run.nuisance_columns) {
      rc.shift[i] = 0.0;
      if (const int slot = shared_slot(run.columns[c]); share && slot >= 0) {
        rc.to[c] = d.columns() + slot;
        if (frame_constant(run.columns[c])) rc.shift[i] = -run.frame_shift;
      }
      continue;
    }
    const int at = column_index(names, run.columns[c]);
    if (at < 0) continue;  // held at neutral: shifted there, then left out
    rc.to[c] = at;
    rc.shift[i] = run.point[i] - z0[at];
  }
  return rc;
}

/// Statistics linearised at a point moved to another `shift` = (point - other point)
/// away: b + M d and yy + 2 d'b + d'M d (the header), in the same columns.
NormalEquations moved(const NormalEquations& ne, const Eigen::VectorXd& shift) {
  NormalEquations out;
  out.set(ne.m(), ne.b() + ne.m() * shift, ne.yy() + 2.0 * shift.dot(ne.b()) + shift.dot(ne.m() * shift), ne.n());
  return out;
}

/// The columns `own` profiled out of `ne` (the Schur complement M_kk - M_ko M_oo^-1 M_ok,
/// b_k - M_ko M_oo^-1 b_o, yy - b_o' M_oo^-1 b_o), over the columns `kept` in that order.
NormalEquations profiled(const NormalEquations& ne, const std::vector<Eigen::Index>& own,
                         const std::vector<Eigen::Index>& kept) {
  Eigen::MatrixXd m = ne.m()(kept, kept);
  Eigen::VectorXd bk = ne.b()(kept);
  double yy = ne.yy();
  if (!own.empty()) {
    const Eigen::LDLT<Eigen::MatrixXd> nn(ne.m()(own, own));
    const Eigen::VectorXd bn = ne.b()(own);
    yy -= bn.dot(nn.solve(bn));
    if (!kept.empty()) {  // Eigen's triangular solve reads element 0 of an empty right-hand side
      const Eigen::MatrixXd ns = ne.m()(own, kept);
      m -= ns.transpose() * nn.solve(ns);
      bk -= ns.transpose() * nn.solve(bn);
    }
  }
  NormalEquations out;
  out.set(std::move(m), std::move(bk), std::max(0.0, yy), ne.n());
  return out;
}

/// The run's constants of one group that are its own: those its rows carry (a constant
/// of another group's signal has an empty column here) and not shared with its log.
std::vector<Eigen::Index> constants_in(const NormalEquations& ne, int nuisance_columns, const RunColumns& rc) {
  std::vector<Eigen::Index> out;
  for (Eigen::Index j = 0; j < nuisance_columns; ++j) {
    if (ne.m()(j, j) > 0.0 && rc.to[static_cast<std::size_t>(j)] < 0) out.push_back(j);
  }
  return out;
}

/// One group's statistics of a run moved to the design's point (b + M d, yy + 2 d'b +
/// d'M d: header) and with the run's own constants profiled out: over `k_out` columns
/// (the design's, then the log's shared constants). Exact: a constant enters one group's
/// signal only, so profiling group by group is profiling the weighted sum.
NormalEquations reduce_run(const NormalEquations& ne, const RunColumns& rc, int nuisance_columns, int k_out) {
  std::vector<Eigen::Index> kept;
  for (std::size_t c = 0; c < rc.to.size(); ++c) {
    if (rc.to[c] >= 0) kept.push_back(static_cast<Eigen::Index>(c));
  }
  const NormalEquations p = profiled(moved(ne, rc.shift), constants_in(ne, nuisance_columns, rc), kept);
  Eigen::MatrixXd mo = Eigen::MatrixXd::Zero(k_out, k_out);
  Eigen::VectorXd bo = Eigen::VectorXd::Zero(k_out);
  for (std::size_t i = 0; i < kept.size(); ++i) {
    const int ti = rc.to[static_cast<std::size_t>(kept[i])];
    bo[ti] = p.b()[static_cast<Eigen::Index>(i)];
    for (std::size_t j = 0; j < kept.size(); ++j) {
      mo(ti, rc.to[static_cast<std::size_t>(kept[j])]) = p.m()(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j));
    }
  }
  NormalEquations out;
  out.set(std::move(mo), std::move(bo), p.yy(), ne.n());
  return out;
}

/// A log's summed statistics with its shared constants (the columns from `k_design` on that
/// its rows carry) profiled out: over the design's columns.
NormalEquations profile_shared(const NormalEquations& ne, int k_design) {
  std::vector<Eigen::Index> own, kept;
  for (Eigen::Index j = 0; j < k_design; ++j) kept.push_back(j);
  for (Eigen::Index j = k_design; j < ne.m().rows(); ++j) {
    if (ne.m()(j, j) > 0.0) own.push_back(j);
  }
  return profiled(ne, own, kept);
}

/// The shared constants of a log's runs at the solution (M_ss^-1 (b_s - M_sk ds) of the group
/// that carries each, in the log's frame): NaN where none.
std::vector<double> shared_constants_at(const Design& d, const Eigen::VectorXd& dz, const std::vector<RunStatistics>& runs,
                                    const std::vector<std::size_t>& members) {
  const Eigen::VectorXd z0 = d.z();
  const int k = d.columns();
  std::vector<double> out(kSharedConstants, kNaN);
  std::vector<RunColumns> columns;
  columns.reserve(members.size());
  for (const std::size_t r : members) columns.push_back(run_columns(runs[r], d, z0, true));
  for (std::size_t g = 0; g < static_cast<std::size_t>(kGroups); ++g) {
    NormalEquations sum(k + kSharedConstants);
    for (std::size_t i = 0; i < members.size(); ++i) {
      const RunStatistics& run = runs[members[i]];
      sum.merge(reduce_run(run.stats.all[g], columns[i], run.nuisance_columns, k + kSharedConstants));
    }
    std::vector<Eigen::Index> own;
    for (Eigen::Index j = k; j < k + kSharedConstants; ++j) {
      if (sum.m()(j, j) > 0.0) own.push_back(j);
    }
    if (own.empty()) continue;
    const Eigen::VectorXd b = sum.b()(own) - sum.m()(own, Eigen::seqN(0, k)) * dz;
    const Eigen::VectorXd v = sum.m()(own, own).ldlt().solve(b);
    for (std::size_t i = 0; i < own.size(); ++i) out[static_cast<std::size_t>(own[i] - k)] = v[static_cast<Eigen::Index>(i)];
  }
  return out;
}

}  // namespace

RunsByLog runs_by_log(std::size_t runs, std::span<const int> log_of) {
  RunsByLog out;
  std::map<int, std::size_t> at;
  for (std::size_t r = 0; r < runs; ++r) {
    const int log = r < log_of.size() ? log_of[r] : -1;
    if (log < 0 || at.find(log) == at.end()) {
      if (log >= 0) at[log] = out.size();
      out.emplace_back();
    }
    out[log < 0 ? out.size() - 1 : at[log]].push_back(r);
  }
  return out;
}

MergedStatistics assemble(const Design& d, const std::vector<RunStatistics>& runs, const RunsByLog& logs) {
  const Eigen::VectorXd z0 = d.z();
  MergedStatistics out(d.columns());
  for (const std::vector<std::size_t>& members : logs) {
    const bool share = members.size() > 1;
    const int k_out = d.columns() + (share ? kSharedConstants : 0);
    MergedStatistics log(k_out);
    for (const std::size_t r : members) {
      const RunStatistics& run = runs[r];
      const RunColumns rc = run_columns(run, d, z0, share);
      for (std::size_t g = 0; g < static_cast<std::size_t>(kGroups); ++g) {
        log.all[g].merge(reduce_run(run.stats.all[g], rc, run.nuisance_columns, k_out));
        log.fold_a[g].merge(reduce_run(run.stats.fold_a[g], rc, run.nuisance_columns, k_out));
        log.fold_b[g].merge(reduce_run(run.stats.fold_b(static_cast<Group>(g)), rc, run.nuisance_columns, k_out));
      }
    }
    for (std::size_t g = 0; g < static_cast<std::size_t>(kGroups); ++g) {
      out.all[g].merge(share ? profile_shared(log.all[g], d.columns()) : log.all[g]);
      out.fold_a[g].merge(share ? profile_shared(log.fold_a[g], d.columns()) : log.fold_a[g]);
      out.fold_b[g].merge(share ? profile_shared(log.fold_b[g], d.columns()) : log.fold_b[g]);
    }
  }
  return out;
}

/// Each run's constants at the solution `s` (profiled: M_nn^-1 (b_n - M_ns ds) of the
/// group that carries each), named "...[run]"; the position errors' constants in the
/// log's frame (the frame shift taken off, as nuisance_at_solution). A log's chunks
/// show its shared constants.
std::vector<ModelParameter> constants_at(const Design& d, const StepSolution& s, const std::vector<RunStatistics>& runs,
                                         const std::vector<std::string>& names, const RunsByLog& logs) {
  const Eigen::VectorXd z0 = d.z();
  std::vector<ModelParameter> out;
  for (const std::vector<std::size_t>& members : logs) {
    const bool share = members.size() > 1;
    const std::vector<double> shared = share ? shared_constants_at(d, s.dz, runs, members) : std::vector<double>{};
    for (const std::size_t r : members) {
      const RunStatistics& run = runs[r];
      const RunColumns rc = run_columns(run, d, z0, share);
      Eigen::VectorXd ds = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(run.columns.size()));
      for (std::size_t c = 0; c < rc.to.size(); ++c) {
        if (rc.to[c] >= 0 && rc.to[c] < d.columns()) ds[static_cast<Eigen::Index>(c)] = s.dz[rc.to[c]];
      }
      Eigen::VectorXd value = Eigen::VectorXd::Constant(run.nuisance_columns, kNaN);
      for (const NormalEquations& ne : run.stats.all) {
        const std::vector<Eigen::Index> own = constants_in(ne, run.nuisance_columns, rc);
        if (own.empty()) continue;
        // b of the moved statistics minus what the shared step explains, over the constants.
        const Eigen::VectorXd b = ne.b() + ne.m() * rc.shift - ne.m() * ds;
        const Eigen::VectorXd dn = ne.m()(own, own).ldlt().solve(Eigen::VectorXd(b(own)));
        for (std::size_t i = 0; i < own.size(); ++i) value[own[i]] = dn[static_cast<Eigen::Index>(i)];
      }
      for (int j = 0; j < run.nuisance_columns; ++j) {
        const std::string& column = run.columns[static_cast<std::size_t>(j)];
        double v = value[j];
        if (const int slot = shared_slot(column); share && slot >= 0) {
          v = shared[static_cast<std::size_t>(slot)];
        } else if (frame_constant(column)) {
          v -= run.frame_shift;
        }
        out.push_back({column + "[" + names[r] + "]", v, kNaN, ""});
      }
    }
  }
  return out;
}

}  // namespace resolver
