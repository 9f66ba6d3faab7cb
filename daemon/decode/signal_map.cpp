#include "daemon/decode/signal_map.h"

namespace resolver {

namespace {
constexpr std::array<std::string_view, kRoleCount> kRoleNames = {"sin", "cos", "rd_angle", "i_a",
                                                                 "i_b", "i_c", "ref_angle"};
}

std::string_view role_name(Role role) { return kRoleNames[static_cast<std::size_t>(role)]; }

std::optional<Role> role_from_name(std::string_view name) {
  for (std::size_t i = 0; i < kRoleCount; ++i) {
    if (kRoleNames[i] == name) return static_cast<Role>(i);
  }
  return std::nullopt;
}

SignalMap SignalMap::bench_default() {
  SignalMap m;
  auto set = [&m](Role r, const char* msg, const char* sig) {
    m.roles[static_cast<std::size_t>(r)] = SignalRef{msg, sig};
  };
  set(Role::kSin, "RESOLVER_SAMPLE", "sin");
  set(Role::kCos, "RESOLVER_SAMPLE", "cos");
  set(Role::kRdAngle, "RESOLVER_SAMPLE", "rd_angle");
  set(Role::kIA, "PHASE_CURRENTS", "i_a");
  set(Role::kIB, "PHASE_CURRENTS", "i_b");
  set(Role::kIC, "PHASE_CURRENTS", "i_c");
  set(Role::kRefAngle, "REFERENCE_ANGLE", "ref_angle");
  return m;
}

}  // namespace resolver
