#include "daemon/core/discovery/coverage.h"

#include <algorithm>
#include <vector>

#include <fmt/format.h>

#include "daemon/core/angles.h"

namespace resolver {

HarmonicOrders needed_orders(const ModelTerm& term) { return term.effect->orders(term.params); }

HarmonicOrders needed_orders(const ModelSpec& spec) {
  HarmonicOrders out;
  for (const ModelTerm& t : spec.terms) {
    const HarmonicOrders o = needed_orders(t);
    out.theta = std::max(out.theta, o.theta);
    out.theta_m = std::max(out.theta_m, o.theta_m);
    out.theta_e = std::max(out.theta_e, o.theta_e);
  }
  return out;
}

namespace {

/// "" when every bin of the angle is seen, else the missing ranges in degrees.
std::string check_one(std::span<const FitRow> rows, int order, double SignatureRow::*angle, const char* what,
                      const char* meaning) {
  if (order <= 0) return "";
  const int bins = 2 * order;
  std::vector<std::int64_t> seen(static_cast<std::size_t>(bins), 0);
  for (const FitRow& r : rows) {
    if (!r.fitted()) continue;
    const int b = std::clamp(static_cast<int>(wrap_2pi(r.sig.*angle) / kTwoPi * bins), 0, bins - 1);
    ++seen[static_cast<std::size_t>(b)];
  }
  std::string gaps;
  int empty = 0;
  for (int b = 0; b < bins;) {
    if (seen[static_cast<std::size_t>(b)] > 0) {
      ++b;
      continue;
    }
    int e = b;
    while (e < bins && seen[static_cast<std::size_t>(e)] == 0) ++e;
    empty += e - b;
    gaps += fmt::format("{}{:.0f}-{:.0f} deg", gaps.empty() ? "" : ", ", 360.0 * b / bins, 360.0 * e / bins);
    b = e;
  }
  if (empty == 0) return "";
  return fmt::format("the moving samples cover {} of {} bins of {} (none at {}): {} up to order {} need every bin; "
                     "fit lower orders or record the whole turn",
                     bins - empty, bins, what, gaps, meaning, order);
}

}  // namespace

CoverageCheck check_coverage(std::span<const FitRow> rows, const HarmonicOrders& need) {
  CoverageCheck out;
  for (const std::string& m :
       {check_one(rows, need.theta, &SignatureRow::theta, "the resolver angle theta", "harmonics of theta"),
        check_one(rows, need.theta_m, &SignatureRow::theta_m, "the mechanical angle theta_m",
                  "mechanical harmonics"),
        check_one(rows, need.theta_e, &SignatureRow::theta_e, "the motor angle theta_e", "current harmonics")}) {
    if (m.empty()) continue;
    out.ok = false;
    out.missing += (out.missing.empty() ? "" : "; ") + m;
  }
  return out;
}

}  // namespace resolver
