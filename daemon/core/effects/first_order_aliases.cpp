#include "daemon/core/effects/first_order_aliases.h"

#include <fmt/format.h>

#include "daemon/core/effects/harmonics.h"
#include "daemon/core/effects/mechanical_harmonics.h"

namespace resolver {

std::vector<std::string> winding_terms_at_order(int m) {
  std::vector<std::string> out;
  if (m < 1) return out;
  if (m + 1 <= kHarmonicsMaxOrder) out.push_back(fmt::format("harmonics(k{0},k{0}_q)", m + 1));
  if (m == 1) {
    out.emplace_back("offsets");
  } else if (m == 2) {
    out.emplace_back("amplitude_imbalance");
    out.emplace_back("quadrature");
  } else if (m - 1 <= kHarmonicsMaxOrder) {
    out.push_back(fmt::format("harmonics(k{0}_opp,k{0}_opp_q)", m - 1));
  }
  return out;
}

std::vector<std::string> rotation_terms_at_order(int m, int p_r) {
  std::vector<std::string> out;
  const int n = m * p_r;
  if (m < 1 || p_r < 1 || n > kMaxMechanicalOrder) return out;
  out.push_back(fmt::format("mechanical_harmonics(a{0},b{0})", n));
  if (n == 1) out.emplace_back("eccentricity");
  return out;
}

}  // namespace resolver
