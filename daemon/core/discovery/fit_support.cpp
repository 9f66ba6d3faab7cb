#include "daemon/core/discovery/fit_support.h"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <cstdio>
#include <limits>
#include <stdexcept>

#include "daemon/core/discovery/coverage.h"

namespace resolver {

std::vector<Nuisance> nuisances_for(const PreparedLog& log) {
  std::vector<Nuisance> out;
  // The position error's constant: without a reference the self-calibration's
  // zero, with an unaligned one the reference's own zero (PrepareOptions).
  if (!log.reference_aligned && log.rd) out.push_back(Nuisance::kRdConstant);
  if (!log.reference_aligned && log.sincos) out.push_back(Nuisance::kSaConstant);
  if (log.sincos) out.push_back(Nuisance::kScGain);
  if (log.currents) {
    out.push_back(Nuisance::kIdConstant);
    out.push_back(Nuisance::kIqConstant);
  }
  return out;
}

Design design_for(const Model& model, const PreparedLog& log) {
  Design d = model.design(nuisances_for(log));
  d.set_parts(log.part_count());
  return d;
}

std::vector<int> model_columns(const Design& design) {
  std::vector<int> out;
  out.reserve(static_cast<std::size_t>(design.columns()));
  for (int j = 0; j < design.nuisance_columns(); ++j) out.push_back(j);
  for (std::size_t i = 0; i < design.terms().size(); ++i) {
    if (design.terms()[i].candidate) continue;
    for (int c : term_columns(design, i)) out.push_back(c);
  }
  return out;
}

std::vector<int> term_columns(const Design& design, std::size_t term) {
  std::vector<int> out;
  for (std::size_t k = 0; k < design.terms()[term].params.size(); ++k) {
    out.push_back(design.term_column(term) + static_cast<int>(k));
  }
  return out;
}

std::vector<std::size_t> aliased_terms(const Design& design, std::span<const FitRow> rows, const GroupFloors& floors) {
  PassStatistics stats(design.columns());
  accumulate(design, rows, floors, stats);
  const std::vector<int> all = model_columns(design);
  if (solve_step(stats.all, floors, all).ok) return {};
  std::vector<std::size_t> out;
  for (std::size_t i = 0; i < design.terms().size(); ++i) {
    if (design.terms()[i].candidate) continue;
    const std::vector<int> own = term_columns(design, i);
    std::vector<int> rest;
    std::copy_if(all.begin(), all.end(), std::back_inserter(rest),
                 [&](int c) { return std::find(own.begin(), own.end(), c) == own.end(); });
    if (solve_step(stats.all, floors, rest).ok) out.push_back(i);
  }
  return out;
}

double rms(double rss, std::int64_t n) { return n > 0 ? std::sqrt(rss / static_cast<double>(n)) : 0.0; }

bool groups_explained(const StepSolution& s, const GroupFloors& floors, double ratio) {
  for (int g = 0; g < kGroups; ++g) {
    const double f = floors.of(static_cast<Group>(g));
    if (!(f > 0.0) || s.n[g] == 0) continue;
    if (rms(s.rss[g], s.n[g]) > ratio * f) return false;
  }
  return true;
}

double bic_of(const StepSolution& s) {
  double n = 0.0;
  for (int g = 0; g < kGroups; ++g) n += static_cast<double>(s.n[g]);
  if (n <= 0.0) return 0.0;
  return n * std::log(std::max(s.rss_w, 1e-300) / n) + static_cast<double>(s.k) * std::log(n);
}

void check_model_against_log(const ModelSpec& spec, const PreparedLog& log) {
  for (const ModelTerm& t : spec.terms) {
    const std::string name(t.effect->name());
    if (t.effect->needs_reference() && !log.reference) {
      throw std::invalid_argument("effect '" + name + "' needs the reference angle, which this log does not have");
    }
    if (t.effect->needs_aligned_reference() && !log.reference_aligned) {
      throw std::invalid_argument("effect '" + name + "' is not identifiable here: " +
                                  std::string(kNeedsAlignedReference));
    }
    if (t.effect->current_side() && !log.currents) {
      throw std::invalid_argument("effect '" + name + "' acts on the phase currents, which this log does not have "
                                  "(with a reference angle)");
    }
  }
  const CoverageCheck c = check_coverage(log.rows, needed_orders(spec));
  if (!c.ok) throw std::invalid_argument(c.missing);
}

/// Cross-validated rms of group g: fitted on one fold, evaluated on the other.
double held_back_rms(const PassStatistics& stats, const GroupFloors& floors, std::span<const int> cols, Group g) {
  std::vector<NormalEquations> only_b(kGroups);
  for (int k = 0; k < kGroups; ++k) only_b[static_cast<std::size_t>(k)] = stats.fold_b(static_cast<Group>(k));
  return held_back_rms(stats.fold_a, only_b, floors, cols, g);
}

double held_back_rms(const std::vector<NormalEquations>& fold_a, const std::vector<NormalEquations>& fold_b,
                     const GroupFloors& floors, std::span<const int> cols, Group g) {
  const auto i = static_cast<std::size_t>(g);
  const NormalEquations& a = fold_a[i];
  const NormalEquations& b = fold_b[i];
  if (a.n() == 0 || b.n() == 0) return std::numeric_limits<double>::quiet_NaN();
  const StepSolution fa = solve_step(fold_a, floors, cols);
  const StepSolution fb = solve_step(fold_b, floors, cols);
  if (!fa.ok || !fb.ok) return std::numeric_limits<double>::quiet_NaN();
  return rms(b.rss(fa.dz) + a.rss(fb.dz), a.n() + b.n());
}

std::string num(double v, const char* format) {
  char buf[64];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

double polar_std_error(const DesignTerm& t, std::size_t p, const Eigen::Matrix2d& cov_xy) {
  const auto ps = t.effect->params();
  const bool amplitude = ps[p].polar == Polar::kAmplitude;
  const std::size_t amp = amplitude ? p : p - 1;
  const double e = t.values[amp], ph = t.values[amp + 1];
  const double x = e * std::cos(ph), y = e * std::sin(ph);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const Eigen::Vector2d j = amplitude ? Eigen::Vector2d(e > 0 ? x / e : 1.0, e > 0 ? y / e : 0.0)
                                      : Eigen::Vector2d(e > 0 ? -y / (e * e) : nan, e > 0 ? x / (e * e) : nan);
  return std::sqrt(std::max(0.0, j.dot(cov_xy * j)));
}

}  // namespace resolver
