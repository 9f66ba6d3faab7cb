#include "tools/model/row_prediction.h"

#include <algorithm>

#include "daemon/core/discovery/fit_support.h"

namespace resolver {

RowPredictor::RowPredictor(const PreparedLog& log, const Model& model) : model_(model) {
  const std::vector<Nuisance> nuisances = nuisances_for(log);
  const auto has = [&](Nuisance n) { return std::find(nuisances.begin(), nuisances.end(), n) != nuisances.end(); };
  SignalValues sum, n;
  for (const FitRow& r : log.rows) {
    if (!r.fitted()) continue;
    const SignalValues p = model_.predict_in_log_frame(r.sig);
    if (r.has(FitRow::kHasRd)) {
      sum.rd += r.y_rd - p.rd;
      n.rd += 1.0;
    }
    if (r.has(FitRow::kHasSc)) {
      sum.sa += r.y_sa - p.sa;
      // The amplitude scales the modelled radius (design.cpp, kScGain): least squares
      // of y - r on the column 1 + r.
      sum.sr += (r.y_sr - p.sr) * (1.0 + p.sr);
      n.sa += 1.0;
      n.sr += (1.0 + p.sr) * (1.0 + p.sr);
    }
    if (r.has(FitRow::kHasCur)) {
      sum.d += r.y_d - p.d;
      sum.q += r.y_q - p.q;
      n.d += 1.0;
      n.q += 1.0;
    }
  }
  const auto mean = [](double s, double count) { return count > 0.0 ? s / count : 0.0; };
  if (has(Nuisance::kRdConstant)) constants_.rd = mean(sum.rd, n.rd);
  if (has(Nuisance::kSaConstant)) constants_.sa = mean(sum.sa, n.sa);
  if (has(Nuisance::kScGain)) constants_.sr = mean(sum.sr, n.sr);
  if (has(Nuisance::kIdConstant)) constants_.d = mean(sum.d, n.d);
  if (has(Nuisance::kIqConstant)) constants_.q = mean(sum.q, n.q);
}

SignalValues RowPredictor::operator()(const FitRow& row) const {
  SignalValues p = model_.predict_in_log_frame(row.sig);
  const double sr = p.sr + constants_.sr * (1.0 + p.sr);
  p += constants_;
  p.sr = sr;
  return p;
}

}  // namespace resolver
