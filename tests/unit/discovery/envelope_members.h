// A sensor's envelope effects (resolver-sim specs) as the fit's EnvelopeMembers, with the
// chain values they come from: the truth the envelope and loop tests compare the fit with.
#pragma once

#include <string>
#include <vector>

#include "daemon/core/effects/chain_values.h"
#include "daemon/core/effects/registry.h"
#include "daemon/core/model/envelope_spectrum.h"

namespace resolver::test {

struct EnvelopeMembers {
  ChainValues values;
  std::vector<std::vector<double>> storage;  ///< each member's values (members point here)
  std::vector<EnvelopeMember> members;
  /// `specs`: "effect:param=value,..." as resolver-sim takes them.
  explicit EnvelopeMembers(const std::vector<std::string>& specs) {
    for (const std::string& spec : specs) values.apply_spec(spec);
    for (const Effect* e : effect_registry()) {
      if (!e->envelope_only() || !values.active(*e)) continue;
      const Values v = values.of(*e);
      storage.emplace_back(v.begin(), v.end());
    }
    std::size_t k = 0;
    for (const Effect* e : effect_registry()) {
      if (!e->envelope_only() || !values.active(*e)) continue;
      members.push_back(EnvelopeMember{e, storage[k++]});
    }
  }
  EnvelopeMembers(const EnvelopeMembers&) = delete;  // members point into storage
  EnvelopeMembers& operator=(const EnvelopeMembers&) = delete;
};

}  // namespace resolver::test
