// What the fit needs of the motion: the true angle must cover the harmonic orders
// being fitted. Order N of an angle needs samples in every one of 2N equal bins of
// it (moving samples only); with fewer, harmonics of neighbouring orders and the
// constant are not told apart and a fit would answer with numbers the data does
// not support. This replaces "two resolver revolutions": one sweep of p_r = 1, an
// out-and-back of one revolution, or a slow turn all qualify when they cover.
#pragma once

#include <span>
#include <string>

#include "daemon/core/effects/effect.h"
#include "daemon/core/model/fit_row.h"
#include "daemon/core/model/model_spec.h"

namespace resolver {

struct CoverageCheck {
  bool ok = true;
  std::string missing;  ///< what is missing, in words ("" when ok)
};

/// The highest orders the terms of `spec` need.
[[nodiscard]] HarmonicOrders needed_orders(const ModelSpec& spec);
[[nodiscard]] HarmonicOrders needed_orders(const ModelTerm& term);

/// Checks the fitted rows against `need`.
[[nodiscard]] CoverageCheck check_coverage(std::span<const FitRow> rows, const HarmonicOrders& need);

}  // namespace resolver
