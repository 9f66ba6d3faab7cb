#include "daemon/app/run_summary.h"

namespace resolver {

void RunSummary::add(const SampleOutput& out, const SampleProcessor& proc) {
  if (!out.has_angle || !proc.compensating()) return;
  if (!std::isnan(out.eps_ref)) {
    eps_raw.add(out.eps_ref);
    eps_comp.add(wrap_pi(out.eps_ref - out.eps_hat));
  }
  if (out.ripple_updated()) {
    ripple = proc.ripple();
    have_ripple = ripple.raw_valid && ripple.comp_valid;
  }
}

}  // namespace resolver
