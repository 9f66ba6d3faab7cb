#include "daemon/app/run_summary.h"

namespace resolver {

void RunSummary::add(const SampleOutput& out, const SampleProcessor& proc) {
  if (!out.has_angle || !proc.estimator().converged() || proc.active_alpha() == 0.0) return;
  if (!std::isnan(out.eps_ref)) {
    eps_raw.add(out.eps_ref);
    eps_comp.add(wrap_pi(out.eps_ref - out.eps_hat));
  }
  const RippleSet& r = proc.ripple();
  for (std::size_t k = 0; k < 3; ++k) {
    if (out.ripple_raw_updated) {
      id_raw[k].add(r.raw.d[k]);
      iq_raw[k].add(r.raw.q[k]);
    }
    if (out.ripple_comp_updated) {
      id_comp[k].add(r.comp.d[k]);
      iq_comp[k].add(r.comp.q[k]);
    }
    if (out.ripple_ref_updated) {
      id_ref[k].add(r.ref.d[k]);
      iq_ref[k].add(r.ref.q[k]);
    }
  }
}

}  // namespace resolver
