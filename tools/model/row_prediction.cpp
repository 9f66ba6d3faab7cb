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
    const SignalValues p = model_.predict(r.sig);
    if (r.has(FitRow::kHasRd)) {
      sum.rd += r.y_rd - p.rd;
      n.rd += 1.0;
    }
    if (r.has(FitRow::kHasSc)) {
      sum.sa += r.y_sa - p.sa;
      sum.sr += r.y_sr - p.sr;
      n.sa += 1.0;
      n.sr += 1.0;
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
  SignalValues p = model_.predict(row.sig);
  p += constants_;
  return p;
}

}  // namespace resolver
