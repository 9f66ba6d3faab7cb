#include "daemon/app/run_summary.h"

namespace resolver {

void RunSummary::add(const SampleOutput& out, const SampleProcessor& proc, double t) {
  if (!out.has_angle) return;
  if (samples == 0) t_first = t;
  t_last = t;
  ++samples;
  moving += out.moving ? 1 : 0;
  if (proc.compensating()) {
    if (compensated == 0) t_compensation_start = t;
    ++compensated;
  }
  if (!std::isnan(out.eps_ref)) {
    ++with_reference;
    raw_all.add(out.eps_ref, t);
    if (out.moving) raw_moving.add(out.eps_ref, t);
    if (out.moving && proc.compensating()) {
      compared_raw.add(out.eps_ref, t);
      compared_comp.add(wrap_pi(out.eps_ref - out.eps_hat), t);
    }
  }
  current_spikes = proc.current_spikes();
  if (!proc.compensating()) return;
  if (out.ripple_updated()) {
    ripple = proc.ripple();
    have_ripple = ripple.raw_valid && ripple.comp_valid;
  }
}

}  // namespace resolver
